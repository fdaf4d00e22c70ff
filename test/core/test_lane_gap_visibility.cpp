// Whether frames saw the gap between two lane fragments (lane_gap_visibility.h): a gap on
// the road ahead of a forward camera is seen, the same gap behind the camera, beside it
// beyond the range or with no camera known is not (or counts as seen), a sliver of it shorter
// than a line the tracker would map is not, and the frames looked at are those between the
// fragments plus the look-around travel.
#include <gtest/gtest.h>

#include <cmath>

#include "common/road_scene.h"
#include "ipm_road_mapper/core/mapper/lane_gap_visibility.h"

namespace ipm_road_mapper {
namespace {

// Frames every 1 m along +x from x0, heading `yaw` (rad).
std::vector<FrameRecord> FramesAlongX(double x0, std::size_t count, double yaw = 0.0) {
  std::vector<FrameRecord> frames(count);
  for (std::size_t i = 0; i < count; ++i) {
    frames[i].index = i;
    frames[i].T_map_base = Eigen::Translation3d(x0 + static_cast<double>(i), 0.0, 0.0) *
                           Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ());
  }
  return frames;
}

// A gap of line 1.75 m left of the path over x in [x0, x1], every 1 m.
std::vector<Eigen::Vector3d> GapPoints(double x0, double x1, double y = 1.75) {
  std::vector<Eigen::Vector3d> points;
  for (double x = x0; x <= x1; x += 1.0) points.emplace_back(x, y, 0.0);
  return points;
}

GapCamera ForwardCamera() {
  GapCamera camera;
  camera.camera = PinholeCamera(test::TestCamera());
  camera.T_base_cam = test::TestExtrinsic();
  return camera;
}

TEST(LaneGapVisibility, AGapOnTheRoadAheadIsSeen) {
  const std::vector<FrameRecord> frames = FramesAlongX(0.0, 40);
  const std::size_t seen =
      FramesThatSawGap(GapPoints(40.0, 60.0), frames, {0, 40}, ForwardCamera(), GapViewOptions());
  // The frames that had the gap at a usable range (Omega_p score <= 1 m^2: within about 16 m
  // for this camera), not the farther ones.
  EXPECT_GE(seen, 10u);
  EXPECT_LE(seen, 25u);
}

TEST(LaneGapVisibility, AGapBehindBesideOrBeyondTheRangeIsNotSeen) {
  const GapCamera camera = ForwardCamera();
  // Heading away from it (a turn done), or looking to the right of a line on the left.
  EXPECT_EQ(FramesThatSawGap(GapPoints(40.0, 60.0), FramesAlongX(0.0, 40, M_PI), {0, 40}, camera,
                             GapViewOptions()),
            0u);
  EXPECT_EQ(FramesThatSawGap(GapPoints(40.0, 60.0), FramesAlongX(30.0, 20, -M_PI / 2), {0, 20},
                             camera, GapViewOptions()),
            0u);
  // 60 m beside the path: in the image's side, but beyond the range.
  EXPECT_EQ(FramesThatSawGap(GapPoints(40.0, 60.0, 60.0), FramesAlongX(0.0, 40), {0, 40}, camera,
                             GapViewOptions()),
            0u);
  // Far ahead at a tight point-score bound: in the image, but too uncertain to map a line.
  GapViewOptions strict;
  strict.max_point_score_m2 = 1e-4;
  EXPECT_EQ(FramesThatSawGap(GapPoints(30.0, 40.0), FramesAlongX(0.0, 5), {0, 5}, camera, strict),
            0u);
}

TEST(LaneGapVisibility, ASliverOfTheGapIsNotSeeingIt) {
  // urban's inner line of the turn: one frame had 1 m of the gap in the image's corner, at the
  // edge of the usable range; a line there would have started no lane (min_new_lane_length_m).
  const std::vector<FrameRecord> frames = FramesAlongX(0.0, 1);
  GapViewOptions three_m;
  three_m.min_seen_length_m = 3.0;
  const std::vector<Eigen::Vector3d> sliver = GapPoints(10.0, 11.0);
  EXPECT_EQ(FramesThatSawGap(sliver, frames, {0, 1}, ForwardCamera(), GapViewOptions()), 1u);
  EXPECT_EQ(FramesThatSawGap(sliver, frames, {0, 1}, ForwardCamera(), three_m), 0u);
  // A long one, given by two points out of view (behind the camera and 60 m ahead): its
  // samples between are seen over more than 3 m.
  const std::vector<Eigen::Vector3d> long_gap{{-10.0, 1.75, 0.0}, {60.0, 1.75, 0.0}};
  EXPECT_EQ(FramesThatSawGap(long_gap, frames, {0, 1}, ForwardCamera(), three_m), 1u);
}

TEST(LaneGapVisibility, AGapJustInsideTheImagesEdgeIsSeenOnlyIfItsLineCertainlyWas) {
  // The line 10-14 m ahead, 0.2 m inside the image's left edge (found by projecting): in view
  // as given, but not when it may lie 0.5 m to either side (a bridge between two ends whose
  // offsets from the path disagree: urban seeds 2 and 4, where the line was outside the view).
  const GapCamera camera = ForwardCamera();
  const std::vector<FrameRecord> frames = FramesAlongX(0.0, 1);
  const Eigen::Isometry3d T_cam_base = camera.T_base_cam.inverse();
  double y_edge = 0.0;
  for (double y = 0.0; y < 30.0; y += 0.01) {
    Eigen::Vector2d uv;
    if (!camera.camera.Project(T_cam_base * Eigen::Vector3d(10.0, y, 0.0), &uv) ||
        !camera.camera.InImage(uv, 0.0)) {
      break;
    }
    y_edge = y;
  }
  ASSERT_GT(y_edge, 1.0);
  // Parallel to the left edge's ray through (10, y_edge), 0.2 m to its right.
  std::vector<Eigen::Vector3d> gap;
  for (double x = 10.0; x <= 14.0; x += 0.5) gap.emplace_back(x, (y_edge - 0.2) * x / 10.0, 0.0);
  GapViewOptions options;
  options.min_seen_length_m = 3.0;
  EXPECT_EQ(FramesThatSawGap(gap, frames, {0, 1}, camera, options), 1u);
  options.lateral_uncertainty_m = 0.5;
  EXPECT_EQ(FramesThatSawGap(gap, frames, {0, 1}, camera, options), 0u);
  // Well inside the image, the same uncertainty leaves it seen.
  EXPECT_EQ(FramesThatSawGap(GapPoints(10.0, 14.0), frames, {0, 1}, camera, options), 1u);
}

TEST(LaneGapVisibility, WithoutACameraEveryGapCountsAsSeen) {
  EXPECT_GT(FramesThatSawGap(GapPoints(40.0, 60.0), FramesAlongX(0.0, 40, M_PI), {0, 40},
                             GapCamera(), GapViewOptions()),
            0u);
  // No points or no frames: nothing seen.
  EXPECT_EQ(FramesThatSawGap({}, FramesAlongX(0.0, 40), {0, 40}, ForwardCamera(), GapViewOptions()),
            0u);
  EXPECT_EQ(FramesThatSawGap(GapPoints(40.0, 60.0), {}, {0, 40}, ForwardCamera(), GapViewOptions()),
            0u);
}

TEST(LaneGapVisibility, TheSpanIsTheFramesBetweenAndTheLookAround) {
  const std::vector<FrameRecord> frames = FramesAlongX(0.0, 200);  // 1 m per frame
  const FrameSpan span = GapFrameSpan(frames, 80, 100, 10.0);
  EXPECT_EQ(span.from, 69u);  // the first frame more than 10 m before frame 80
  EXPECT_EQ(span.to, 112u);   // past the first frame more than 10 m after frame 100
  // Either order; clamped to the frames there are.
  const FrameSpan reversed = GapFrameSpan(frames, 100, 80, 10.0);
  EXPECT_EQ(reversed.from, span.from);
  EXPECT_EQ(reversed.to, span.to);
  const FrameSpan clamped = GapFrameSpan(frames, 3, 500, 10.0);
  EXPECT_EQ(clamped.from, 0u);
  EXPECT_EQ(clamped.to, 200u);
  EXPECT_EQ(GapFrameSpan({}, 3, 5, 10.0).to, 0u);
}

TEST(LaneGapVisibility, AStandstillIsCheckedEvenlyNotFrameByFrame) {
  // 5000 frames at one place looking at the gap: all seen, through the strided check.
  std::vector<FrameRecord> frames = FramesAlongX(0.0, 1);
  frames.resize(5000, frames.front());
  GapViewOptions options;
  options.max_frames = 100;
  const std::size_t seen =
      FramesThatSawGap(GapPoints(8.0, 12.0), frames, {0, 5000}, ForwardCamera(), options);
  EXPECT_GE(seen, 4900u);
  EXPECT_LE(seen, 5000u);
}

}  // namespace
}  // namespace ipm_road_mapper
