// The core Mapper end to end on rendered masks: elements are created once and re-observed,
// lanes grow, spurious elements are dropped, and every kind of bad input is skipped with a
// counted reason without touching the map.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "common/road_scene.h"
#include "ipm_road_mapper/core/geometry/ipm.h"
#include "ipm_road_mapper/core/mapper/mapper.h"

namespace ipm_road_mapper {
namespace {

using namespace test;  // NOLINT: the scene's helpers

// The front end alone (the back end has its own tests).
Mapper MakeMapper() {
  MapperOptions options;
  options.backend.enabled = false;
  return Mapper(options, TestClasses(), TestExtrinsic());
}

TEST(Mapper, ReobservedMarkingIsOneElementAtTheRightPlace) {
  Mapper mapper = MakeMapper();
  for (int k = 0; k < 10; ++k) {
    ASSERT_EQ(mapper.ProcessFrame(RoadFrame(100.0 + 0.05 * k, 0.5 * k)), FrameStatus::kUsed);
  }
  ASSERT_EQ(mapper.map().markings.size(), 1u);
  const MarkingElement& arrow = mapper.map().markings[0];
  EXPECT_EQ(arrow.history.size(), 10u);
  EXPECT_NEAR(arrow.Center().x(), 21.5, 0.1);
  EXPECT_NEAR(arrow.Center().y(), 0.0, 0.05);
  // Each measurement's pixel corners are stored in the element's corner order: the
  // first corner of every frame maps to the same ground corner.
  const Ipm ipm(PinholeCamera(TestCamera()), TestExtrinsic(), 100.0);
  for (const MarkingMeasurement& m : arrow.history) {
    Eigen::Vector3d p_base;
    ASSERT_EQ(ipm.PixelToGround(m.corners_uv[0], &p_base), IpmStatus::kOk);
    const Eigen::Vector3d p_map = mapper.map().frames[m.frame_index].T_map_base * p_base;
    EXPECT_LT((p_map - arrow.corners_map[0]).head<2>().norm(), 0.15);
  }
}

// A long stripe seen from shifted odometry lands 1.2 m along the road from its element:
// beyond a tight association gate and beyond the merge distance, but the two ground
// rectangles overlap by 70%, so they are one marking (and two with the overlap test off).
std::size_t StripeElements(double merge_overlap) {
  MapperOptions options;
  options.backend.enabled = false;
  options.association.marking_gate_sigmas = 0.2;
  options.association.marking_merge_overlap = merge_overlap;
  Mapper mapper(options, TestClasses(), TestExtrinsic());
  for (int k = 0; k < 8; ++k) {
    const double x_vehicle = 0.5 * k;
    FrameInput in;
    in.stamp = 100.0 + 0.05 * k;
    in.camera = TestCamera();
    in.mask = cv::Mat::zeros(720, 1280, CV_16UC1);
    FillGround(Rect(20.0, 24.0, -0.25, 0.25), PoseAt(x_vehicle), 10001, &in.mask);
    in.T_map_base_odom = PoseAt(x_vehicle + (k >= 5 ? 1.2 : 0.0));
    EXPECT_EQ(mapper.ProcessFrame(in), FrameStatus::kUsed);
  }
  std::size_t total_observations = 0;
  for (const MarkingElement& m : mapper.map().markings) total_observations += m.history.size();
  EXPECT_EQ(total_observations, 8u);  // nothing lost either way
  return mapper.map().markings.size();
}

TEST(Mapper, OverlappingElementsOfOneClassAreMerged) {
  EXPECT_EQ(StripeElements(0.0), 2u);
  EXPECT_EQ(StripeElements(0.5), 1u);
}

// The lane must be one spline that grows as the vehicle drives. With point selection only
// the near, low-uncertainty points feed g, so the spline reaches about as far as the last
// frame's near range; without it, as far as the camera sees (35 m ahead).
void ExpectDashedLaneGrows(bool point_selection, double min_x_max) {
  MapperOptions options;
  options.backend.enabled = false;
  options.lanes.point_selection = point_selection;
  Mapper mapper(options, TestClasses(), TestExtrinsic());
  for (int k = 0; k < 60; ++k) mapper.ProcessFrame(RoadFrame(100.0 + 0.05 * k, 1.0 * k, false));
  const VectorMap map = mapper.ExportMap();
  ASSERT_EQ(map.lanes.size(), 1u);
  const auto& cps = map.lanes[0].control_points_map;
  ASSERT_GE(cps.size(), 4u);
  double x_min = 1e9, x_max = -1e9;
  for (std::size_t i = 1; i + 1 < cps.size(); ++i) {
    EXPECT_NEAR(cps[i].y(), 1.8, 0.1);
    x_min = std::min(x_min, cps[i].x());
    x_max = std::max(x_max, cps[i].x());
  }
  EXPECT_LT(x_min, 12.0);       // first dashes seen from x = 0
  EXPECT_GT(x_max, min_x_max);  // grown as the vehicle drove 59 m
}

TEST(Mapper, DashedLaneIsOneGrowingSpline) { ExpectDashedLaneGrows(false, 80.0); }

TEST(Mapper, DashedLaneIsOneGrowingSplineWithPointSelection) { ExpectDashedLaneGrows(true, 62.0); }

TEST(Mapper, MarkingSeenOnceIsDroppedAsSpurious) {
  // Seen once, then not where the next frames should have seen it: dropped as inconsistent
  // (MarkingTracker::CheckConsistency), before the seen-once horizon would drop it.
  Mapper mapper = MakeMapper();
  mapper.ProcessFrame(RoadFrame(100.0, 0.0));
  EXPECT_EQ(mapper.map().markings.size(), 1u);
  for (int k = 1; k <= 12; ++k) mapper.ProcessFrame(RoadFrame(100.0 + 0.05 * k, 0.0, false));
  EXPECT_TRUE(mapper.map().markings.empty());
  EXPECT_EQ(mapper.counters().spurious_dropped + mapper.counters().markings_inconsistent, 1u);
}

TEST(Mapper, BadInputIsSkippedCountedAndLeavesTheMap) {
  Mapper mapper = MakeMapper();
  for (int k = 0; k < 3; ++k) mapper.ProcessFrame(RoadFrame(100.0 + 0.05 * k, 0.5 * k));
  const std::size_t markings = mapper.map().markings.size();
  const std::size_t frames = mapper.map().frames.size();
  ASSERT_EQ(markings, 1u);

  std::string reason;
  FrameInput wrong_size = RoadFrame(101.0, 2.0);
  wrong_size.mask = cv::Mat::zeros(480, 640, CV_16UC1);
  EXPECT_EQ(mapper.ProcessFrame(wrong_size, &reason), FrameStatus::kSkipped);
  EXPECT_NE(reason.find("bad_mask"), std::string::npos) << reason;

  FrameInput wrong_encoding = RoadFrame(101.1, 2.0);
  wrong_encoding.mask = cv::Mat::zeros(720, 1280, CV_8UC1);
  EXPECT_EQ(mapper.ProcessFrame(wrong_encoding, &reason), FrameStatus::kSkipped);

  FrameInput nan_pose = RoadFrame(101.2, 2.0);
  nan_pose.T_map_base_odom.translation().x() = std::nan("");
  EXPECT_EQ(mapper.ProcessFrame(nan_pose, &reason), FrameStatus::kSkipped);
  EXPECT_NE(reason.find("bad_pose"), std::string::npos) << reason;

  FrameInput back_in_time = RoadFrame(99.0, 2.0);
  EXPECT_EQ(mapper.ProcessFrame(back_in_time, &reason), FrameStatus::kSkipped);
  EXPECT_NE(reason.find("time_jump"), std::string::npos) << reason;

  FrameInput bad_camera = RoadFrame(101.3, 2.0);
  bad_camera.camera.fx = 0.0;
  EXPECT_EQ(mapper.ProcessFrame(bad_camera, &reason), FrameStatus::kSkipped);

  FrameInput nan_stamp = RoadFrame(101.4, 2.0);
  nan_stamp.stamp = std::nan("");
  EXPECT_EQ(mapper.ProcessFrame(nan_stamp, &reason), FrameStatus::kSkipped);

  EXPECT_EQ(mapper.map().markings.size(), markings);
  EXPECT_EQ(mapper.map().frames.size(), frames);
  const auto& skipped = mapper.counters().frames_skipped;
  EXPECT_EQ(skipped.at("bad_mask"), 2u);
  EXPECT_EQ(skipped.at("bad_pose"), 1u);
  EXPECT_EQ(skipped.at("time_jump"), 1u);
  EXPECT_EQ(skipped.at("bad_camera"), 1u);
  EXPECT_EQ(skipped.at("bad_stamp"), 1u);

  // Still maps after the bad frames.
  EXPECT_EQ(mapper.ProcessFrame(RoadFrame(102.0, 2.0)), FrameStatus::kUsed);
  EXPECT_EQ(mapper.map().markings.size(), 1u);
}

TEST(Mapper, AbsurdMasksAreBounded) {
  Mapper mapper = MakeMapper();
  FrameInput all_foreground = RoadFrame(100.0, 0.0);
  all_foreground.mask.setTo(cv::Scalar(10001));
  EXPECT_EQ(mapper.ProcessFrame(all_foreground), FrameStatus::kUsed);
  EXPECT_TRUE(mapper.map().markings.empty());  // touches the border: truncated

  FrameInput confetti = RoadFrame(100.1, 0.0);
  for (int i = 0; i < 10000; ++i) {
    const int value = 10000 + (i % 30000);  // many classes, many instances
    confetti.mask.at<std::uint16_t>(200 + (i / 1280) * 2 % 500, i % 1280) =
        static_cast<std::uint16_t>(value);
  }
  EXPECT_EQ(mapper.ProcessFrame(confetti), FrameStatus::kUsed);
  const ExtractionCounters& c = mapper.counters().extraction;
  EXPECT_GT(c.dropped_instance_limit + c.dropped_unknown_class + c.dropped_tiny, 0u);
}

TEST(Mapper, ExportCanHoldTheNewestPosesOnly) {
  Mapper mapper = MakeMapper();
  for (int k = 0; k < 6; ++k) mapper.ProcessFrame(RoadFrame(100.0 + 0.05 * k, 0.5 * k));
  EXPECT_EQ(mapper.ExportMap().trajectory.size(), 6u);
  ExportOptions newest;
  newest.max_trajectory_poses = 2;
  const VectorMap map = mapper.ExportMap(newest);
  ASSERT_EQ(map.trajectory.size(), 2u);
  EXPECT_DOUBLE_EQ(map.trajectory.back().stamp, 100.25);
  EXPECT_EQ(map.markings.size(), mapper.ExportMap().markings.size());
}

TEST(Mapper, ResetDropsTheMapButKeepsMapping) {
  Mapper mapper = MakeMapper();
  for (int k = 0; k < 3; ++k) mapper.ProcessFrame(RoadFrame(100.0 + 0.05 * k, 0.5 * k));
  mapper.Reset();
  EXPECT_TRUE(mapper.map().markings.empty());
  EXPECT_TRUE(mapper.map().frames.empty());
  EXPECT_EQ(mapper.ProcessFrame(RoadFrame(50.0, 0.0)), FrameStatus::kUsed);  // time restarts
}

}  // namespace
}  // namespace ipm_road_mapper
