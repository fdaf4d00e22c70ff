// Lane extraction (instance_extraction.h): a straight lane's centerline, a dashed lane as
// one observation, a lane beyond the IPM range.
#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "common/extraction_scene.h"
#include "ipm_road_mapper/core/frontend/instance_extraction.h"

namespace ipm_road_mapper {
namespace {

TEST_F(InstanceExtractionTest, StraightLaneCenterline) {
  cv::Mat mask = EmptyMask();
  RenderLaneStrip(ipm_, 1.8, 4.0, 40.0, 0.15, kSolidLane + 2, &mask);
  const FrameObservations obs = Extract(mask);
  ASSERT_EQ(obs.lanes.size(), 1u);
  EXPECT_TRUE(obs.markings.empty());
  const LaneObservation& lane = obs.lanes[0];
  EXPECT_EQ(lane.class_id, 1);
  EXPECT_EQ(lane.instance_value, kSolidLane + 2);
  EXPECT_EQ(lane.pixel_count, cv::countNonZero(mask));
  ASSERT_GE(lane.points.size(), 50u);

  int increasing_scores = 0;
  for (std::size_t i = 0; i < lane.points.size(); ++i) {
    const LanePoint& p = lane.points[i];
    EXPECT_NEAR(p.p_base.y(), 1.8, 0.05) << "point " << i << " at x " << p.p_base.x();
    EXPECT_EQ(p.p_base.z(), 0.0);
    EXPECT_GE(p.p_base.x(), 4.0 - 0.1);
    EXPECT_LE(p.p_base.x(), 40.0 + 0.5);
    EXPECT_GT(p.score, 0.0);
    if (i == 0) continue;
    const LanePoint& previous = lane.points[i - 1];
    EXPECT_EQ(previous.uv.y() - p.uv.y(), options_.lane_row_step) << "point " << i;
    EXPECT_GT(p.p_base.x(), previous.p_base.x());
    if (p.score > previous.score) ++increasing_scores;
  }
  // Bottom (near) first; the nearest point is at the strip's near end.
  EXPECT_NEAR(lane.points.front().p_base.x(), 4.0, 0.1);
  EXPECT_GT(lane.points.back().p_base.x(), 35.0);
  EXPECT_GE(increasing_scores, static_cast<int>(0.9 * (lane.points.size() - 1)));
  EXPECT_GT(lane.points.back().score, 10.0 * lane.points.front().score);
}

TEST_F(InstanceExtractionTest, DashedLaneIsOneObservation) {
  cv::Mat mask = EmptyMask();
  for (double x = 5.0; x < 40.0; x += 9.0) {
    RenderLaneStrip(ipm_, -1.8, x, x + 3.0, 0.15, kDashedLane + 1, &mask);
  }
  const FrameObservations obs = Extract(mask);
  ASSERT_EQ(obs.lanes.size(), 1u);
  EXPECT_EQ(obs.counters.instances_seen, 1u);
  const LaneObservation& lane = obs.lanes[0];
  ASSERT_GE(lane.points.size(), 20u);
  EXPECT_LT(lane.points.front().p_base.x(), 6.0);
  EXPECT_GT(lane.points.back().p_base.x(), 30.0);
  for (std::size_t i = 0; i < lane.points.size(); ++i) {
    EXPECT_NEAR(lane.points[i].p_base.y(), -1.8, 0.05);
    if (i > 0) {
      EXPECT_LT(lane.points[i].uv.y(), lane.points[i - 1].uv.y());
    }
  }
}

TEST_F(InstanceExtractionTest, LaneBeyondRangeIsDegenerate) {
  options_.min_lane_pixels = 10;
  cv::Mat mask = EmptyMask();
  RenderLaneStrip(ipm_, 1.8, 48.0, 60.0, 0.5, kSolidLane, &mask);
  const FrameObservations obs = Extract(mask);
  EXPECT_TRUE(obs.lanes.empty());
  EXPECT_EQ(obs.counters.dropped_degenerate, 1u);
}

}  // namespace
}  // namespace ipm_road_mapper
