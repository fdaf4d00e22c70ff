// The window's lane pixels: each is assigned to the spline segment where its ray meets the
// road, also where the road ahead is not in the viewing frame's plane (a crest, a pitched
// body): on the lane's own surface (the opt-in) and on the viewing frame's front-end ground.
#include <gtest/gtest.h>

#include <cmath>

#include "common/test_scene.h"
#include "ipm_road_mapper/core/backend/window_measurements.h"
#include "ipm_road_mapper/core/backend/window_state.h"
#include "ipm_road_mapper/core/geometry/pinhole_camera.h"

namespace ipm_road_mapper {
namespace {

constexpr double kDeg = M_PI / 180.0;

// The height of a road over a crest (+6 % grade turning at 0.1 %/m): z(x) = 0.06 x -
// 0.0005 x^2, i.e. 0.8 m below the viewing frame's plane at 40 m.
double CrestHeight(double x_m) { return 0.06 * x_m - 0.0005 * x_m * x_m; }

// A lane at y_m beside the path, its control points on the crest every 3 m from -6 m to 60 m.
WindowLane LaneOverCrest(double y_m) {
  WindowLane lane;
  for (double x = -6.0; x <= 60.0; x += 3.0) {
    lane.control_points_map.emplace_back(x, y_m, CrestHeight(x));
  }
  return lane;
}

// One frame at the origin on the crest's first slope (nose up: its base plane has the 6 %
// grade), seeing the lane at 3.5 m to the left.
WindowSnapshot CrestSnapshot(const std::vector<double>& x_on_lane_m) {
  WindowSnapshot snapshot;
  snapshot.camera = test::Intrinsics1280x720();
  snapshot.T_base_cam = test::MountedCamera(0.0, 4.0 * kDeg, 0.0, Eigen::Vector3d(1.5, 0.0, 1.5));
  WindowFrame frame;
  frame.index = 7;
  frame.T_map_base.linear() = RotationFromRpy(0.0, -std::atan(0.06), 0.0);
  snapshot.frames.push_back(frame);
  WindowLane lane = LaneOverCrest(3.5);
  const PinholeCamera camera(snapshot.camera);
  const Eigen::Isometry3d T_cam_map = (frame.T_map_base * snapshot.T_base_cam).inverse();
  LaneMeasurement measurement;
  measurement.frame_index = frame.index;
  for (double x : x_on_lane_m) {
    LanePoint point;
    EXPECT_TRUE(camera.Project(Eigen::Vector3d(T_cam_map * Eigen::Vector3d(x, 3.5, CrestHeight(x))),
                               &point.uv));
    measurement.points.push_back(point);
    measurement.selected.push_back(1);
  }
  lane.measurements.push_back(measurement);
  snapshot.lanes.push_back(lane);
  return snapshot;
}

// A straight level lane 3.5 m left of one frame (a camera mounted pitched 4 deg) and one pixel of
// it: the point x_m ahead seen by the camera at T_map_base * T_base_cam_seen.
WindowSnapshot FlatLaneSnapshot(const WindowFrame& frame, const Eigen::Isometry3d& T_base_cam_seen,
                                double x_m) {
  WindowSnapshot snapshot;
  snapshot.camera = test::Intrinsics1280x720();
  snapshot.T_base_cam = test::MountedCamera(0.0, 4.0 * kDeg, 0.0, Eigen::Vector3d(1.5, 0.0, 1.5));
  snapshot.frames.push_back(frame);
  WindowLane lane;
  for (double x = -6.0; x <= 60.0; x += 3.0) lane.control_points_map.emplace_back(x, 3.5, 0.0);
  LaneMeasurement measurement;
  measurement.frame_index = frame.index;
  LanePoint point;
  const Eigen::Isometry3d T_cam_map = (frame.T_map_base * T_base_cam_seen).inverse();
  EXPECT_TRUE(PinholeCamera(snapshot.camera)
                  .Project(Eigen::Vector3d(T_cam_map * Eigen::Vector3d(x_m, 3.5, 0.0)), &point.uv));
  measurement.points.push_back(point);
  measurement.selected.push_back(1);
  lane.measurements.push_back(measurement);
  snapshot.lanes.push_back(lane);
  return snapshot;
}

TEST(CollectLanePixels, AssignsAPixelBeyondACrestToTheSegmentItsRayMeets) {
  const std::vector<double> x_true = {12.0, 16.5, 25.0, 31.0};
  const WindowSnapshot snapshot = CrestSnapshot(x_true);
  BackendOptions options;
  options.max_lane_points_per_observation = 100;
  options.lane_pixels_on_lane_surface = true;
  window_solve::WindowState state(snapshot);
  window_solve::CollectLanePixels(snapshot, options, &state);
  // Flat-ground IPM puts the pixel at 31 m about 6 m too far, and 0.7 m sideways: it was
  // given the segment two chords on, or dropped by the 1.5 m gate.
  ASSERT_EQ(state.lane_pixels.size(), x_true.size());
  for (std::size_t i = 0; i < x_true.size(); ++i) {
    const window_solve::LanePixel& pixel = state.lane_pixels[i];
    // Control point k + 1 is the segment's start: x = -6 + 3 (segment + 1).
    const double x_start = -6.0 + 3.0 * (pixel.segment + 1);
    EXPECT_LE(x_start, x_true[i] + 1e-6) << "pixel at x = " << x_true[i];
    EXPECT_GE(x_start + 3.0, x_true[i] - 1e-6) << "pixel at x = " << x_true[i];
    EXPECT_NEAR(pixel.q_map.x(), x_true[i], 0.05);
    EXPECT_NEAR(pixel.q_map.y(), 3.5, 0.05);
    EXPECT_NEAR(pixel.q_map.z(), CrestHeight(x_true[i]), 0.01);
  }
}

TEST(CollectLanePixels, TakesTheViewingFramesFrontEndGround) {
  // One frame, pitched 0.3 deg nose down on flat ground, its front end's ground the road
  // (level): a pixel of a line 31 m ahead goes onto that ground, not onto the pitched plane
  // of base_link, which puts it 2 m farther.
  WindowFrame frame;
  frame.index = 3;
  frame.T_map_base.linear() = RotationFromRpy(0.0, 0.3 * kDeg, 0.0);
  frame.ground_base.normal = frame.T_map_base.linear().transpose() * Eigen::Vector3d::UnitZ();
  const WindowSnapshot snapshot = FlatLaneSnapshot(
      frame, test::MountedCamera(0.0, 4.0 * kDeg, 0.0, Eigen::Vector3d(1.5, 0.0, 1.5)), 31.0);
  BackendOptions options;
  window_solve::WindowState state(snapshot);
  window_solve::CollectLanePixels(snapshot, options, &state);
  ASSERT_EQ(state.lane_pixels.size(), 1u);
  EXPECT_NEAR(state.lane_pixels[0].q_map.x(), 31.0, 1e-6);
  EXPECT_NEAR(state.lane_pixels[0].q_map.y(), 3.5, 1e-6);
  EXPECT_EQ(state.lane_pixels[0].segment, 11);  // control points 12 and 13: x = 30 and 33 m
}

TEST(RefreshPsrPoints, ReIpmsThePointWithTheExtrinsicTheSolveRefined) {
  // A line 25 m ahead seen by a camera pitched 4.3 deg; the window begins with 4.0 deg, which
  // puts its IPM point about 2.5 m too far. Once the solve has the true pitch, the PSR point
  // (what PSR measures) must be re-IPMed with it, and go to the segment it falls on.
  const Eigen::Isometry3d T_base_cam_true =
      test::MountedCamera(0.0, 4.3 * kDeg, 0.0, Eigen::Vector3d(1.5, 0.0, 1.5));
  WindowFrame frame;
  frame.index = 5;
  const WindowSnapshot snapshot = FlatLaneSnapshot(frame, T_base_cam_true, 25.0);
  BackendOptions options;
  options.lane_residual = LaneResidual::kPsr;
  window_solve::WindowState state(snapshot);
  window_solve::CollectLanePixels(snapshot, options, &state);
  ASSERT_EQ(state.lane_pixels.size(), 1u);
  EXPECT_GT(state.lane_pixels[0].q_map.x(), 26.0);  // the window's extrinsic: too far
  state.extrinsic = window_solve::PoseBlocks(T_base_cam_true);
  window_solve::RefreshPsrPoints(snapshot, options, &state);
  const window_solve::LanePixel& pixel = state.lane_pixels[0];
  EXPECT_NEAR(pixel.q_map.x(), 25.0, 1e-6);
  EXPECT_NEAR(pixel.q_map.y(), 3.5, 1e-6);
  EXPECT_NEAR((pixel.p_base - pixel.q_map).norm(), 0.0, 1e-9);  // the frame is at the origin
  EXPECT_EQ(pixel.segment, 9);  // control points 10 and 11: x = 24 and 27 m
  EXPECT_NEAR(pixel.u, 1.0 / 3.0, 0.02);
}

}  // namespace
}  // namespace ipm_road_mapper
