// The debug overlay: a mapped marking that agrees with the mask projects onto its measured
// corners (residual near zero); one mapped 0.5 m off shows a residual of many pixels; a
// mapped lane is matched by the measured lane pixels; bad camera/pose input gives an image.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "common/mask_test_utils.h"
#include "ipm_road_mapper/core/geometry/ipm.h"
#include "ipm_road_mapper/pipeline/debug_overlay.h"

namespace ipm_road_mapper {
namespace {

ClassTable Classes() {
  return ClassTable::Load(OptionsReader(YAML::Load(R"(
classes:
  - {id: 2, name: lane_white_dashed, kind: lane, style: dashed}
  - {id: 10, name: arrow_straight, kind: marking}
)"),
                                        ""));
}

// Labels every pixel whose ground point (IPM, z = 0 in base_link = map) lies in the box.
void FillGroundBox(double x0, double x1, double y0, double y1, int value, cv::Mat* mask) {
  const Ipm ipm = test::TestIpm();
  for (int row = 0; row < mask->rows; ++row) {
    for (int col = 0; col < mask->cols; ++col) {
      Eigen::Vector3d p;
      if (ipm.PixelToGround(Eigen::Vector2d(col, row), &p) != IpmStatus::kOk) continue;
      if (p.x() >= x0 && p.x() <= x1 && p.y() >= y0 && p.y() <= y1) {
        mask->at<std::uint16_t>(row, col) = static_cast<std::uint16_t>(value);
      }
    }
  }
}

MapMarking Marking(double x0, double x1, double y0, double y1) {
  MapMarking m;
  m.id = 7;
  m.class_id = 10;
  m.class_name = "arrow_straight";
  m.corners_map = {Eigen::Vector3d(x0, y0, 0), Eigen::Vector3d(x1, y0, 0),
                   Eigen::Vector3d(x1, y1, 0), Eigen::Vector3d(x0, y1, 0)};
  return m;
}

MapLane StraightLane(double y) {
  MapLane lane;
  lane.id = 3;
  lane.class_id = 2;
  for (double x = 0.0; x <= 30.0; x += 3.0) lane.control_points_map.emplace_back(x, y, 0.0);
  return lane;
}

OverlayFrame Frame(const cv::Mat& mask) {
  OverlayFrame frame;
  frame.mask = mask;
  frame.camera = test::TestCamera().intrinsics();
  frame.T_base_cam = test::TestTBaseCam();
  return frame;
}

MapperOptions Options() {
  MapperOptions options;
  options.ipm.max_range_m = 50.0;
  return options;
}

TEST(DebugOverlay, MatchingMarkingHasSmallResidualAndShiftedOneLarge) {
  cv::Mat mask = test::EmptyMask();
  FillGroundBox(10.0, 13.0, -0.6, 0.6, 10001, &mask);
  const OverlayFrame frame = Frame(mask);
  const FrameObservations measured =
      MeasureFrame(mask, frame.camera, frame.T_base_cam, Classes(), Options());
  ASSERT_EQ(measured.markings.size(), 1u);

  VectorMap map;
  map.markings.push_back(Marking(10.0, 13.0, -0.6, 0.6));
  OverlayStats stats;
  const cv::Mat image = DrawDebugOverlay(frame, measured, map, &stats);
  EXPECT_EQ(image.type(), CV_8UC3);
  EXPECT_EQ(image.cols, 1280);
  EXPECT_EQ(image.rows, 720);
  EXPECT_EQ(stats.markings_projected, 1);
  EXPECT_EQ(stats.markings_measured, 1);
  EXPECT_EQ(stats.marking_matches, 1);
  EXPECT_LT(stats.mean_corner_residual_px, 2.0);
  const double matched_px = stats.mean_corner_residual_px;

  // 0.5 m farther: with the camera 1.5 m high and pitched 5 deg, rows move by about 7 px at
  // 10 m and 4 px at 13 m.
  map.markings[0] = Marking(10.5, 13.5, -0.6, 0.6);
  DrawDebugOverlay(frame, measured, map, &stats);
  EXPECT_EQ(stats.marking_matches, 1);
  EXPECT_GT(stats.mean_corner_residual_px, 4.0);
  EXPECT_GT(stats.mean_corner_residual_px, matched_px + 3.0);
}

TEST(DebugOverlay, LanePixelsMatchTheProjectedLane) {
  cv::Mat mask = test::EmptyMask();
  FillGroundBox(4.0, 30.0, 1.6, 1.75, 2001, &mask);
  const OverlayFrame frame = Frame(mask);
  const FrameObservations measured =
      MeasureFrame(mask, frame.camera, frame.T_base_cam, Classes(), Options());
  ASSERT_EQ(measured.lanes.size(), 1u);
  VectorMap map;
  map.lanes.push_back(StraightLane(1.675));
  OverlayStats stats;
  DrawDebugOverlay(frame, measured, map, &stats);
  EXPECT_GE(stats.lanes_projected, 1);
  EXPECT_GT(stats.lane_points_measured, 10);
  EXPECT_EQ(stats.lane_point_matches, stats.lane_points_measured);
  EXPECT_LT(stats.mean_lane_residual_px, 2.0);

  map.lanes[0] = StraightLane(1.675 + 0.5);  // half a meter to the left
  DrawDebugOverlay(frame, measured, map, &stats);
  EXPECT_GT(stats.mean_lane_residual_px, 5.0);
}

// A lane stretch no pixel measured (laid by a join) is drawn grey, the rest green.
TEST(DebugOverlay, ALaidLaneStretchIsDrawnGrey) {
  const cv::Mat mask = test::EmptyMask();
  const OverlayFrame frame = Frame(mask);
  const FrameObservations measured =
      MeasureFrame(mask, frame.camera, frame.T_base_cam, Classes(), Options());
  VectorMap map;
  map.lanes.push_back(StraightLane(-2.0));
  OverlayStats stats;
  const auto count = [](const cv::Mat& image, const cv::Scalar& bgr) {
    cv::Mat hits;
    cv::inRange(image, bgr, bgr, hits);
    return cv::countNonZero(hits);
  };
  const cv::Scalar green(0, 220, 0), grey(160, 160, 160);
  const cv::Mat measured_lane = DrawDebugOverlay(frame, measured, map, &stats);
  EXPECT_GT(count(measured_lane, green), 100);
  EXPECT_EQ(count(measured_lane, grey), 0);
  map.lanes[0].unmeasured = {{4, 6}};  // x 12-18 m: the curve from 9 to 21 m is laid
  const cv::Mat laid = DrawDebugOverlay(frame, measured, map, &stats);
  EXPECT_GT(count(laid, grey), 50);
  EXPECT_GT(count(laid, green), 50);
  EXPECT_LT(count(laid, green), count(measured_lane, green));
}

TEST(DebugOverlay, BadInputGivesAnImageNotACrash) {
  OverlayFrame frame = Frame(test::EmptyMask());
  OverlayStats stats;
  frame.T_map_base.matrix()(0, 3) = std::nan("");
  cv::Mat image = DrawDebugOverlay(frame, FrameObservations(), VectorMap(), &stats);
  EXPECT_EQ(image.cols, 1280);
  frame.camera.fx = 0.0;
  image = DrawDebugOverlay(frame, FrameObservations(), VectorMap(), &stats);
  EXPECT_FALSE(image.empty());
  // A mask of the wrong size measures nothing.
  const cv::Mat small(10, 10, CV_16UC1, cv::Scalar(10001));
  EXPECT_TRUE(MeasureFrame(small, Frame(small).camera, test::TestTBaseCam(), Classes(), Options())
                  .markings.empty());
}

}  // namespace
}  // namespace ipm_road_mapper
