// Well-formed but absurd masks (docs/architecture.md "Bad input"): what no real lane line or
// marking produces is dropped by the extraction and counted by reason, and no map element
// comes of it; a frame whose foreground is absurd as a whole gives no observation while its
// pose is still used.
// The Mapper on such frames and the options of the checks: test_absurd_frames.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "common/class_values.h"
#include "common/road_scene.h"
#include "ipm_road_mapper/core/frontend/instance_extraction.h"
#include "ipm_road_mapper/core/mapper/mapper.h"

namespace ipm_road_mapper {
namespace {

using test::FillGround;
using test::PoseAt;
using test::Rect;

// Mask values of config/classes.yaml: 1 lane_white_solid, 10 arrow_straight, 21 stop_line.
constexpr std::uint16_t kSolidLane = 1 * kInstanceIdFactor;
constexpr std::uint16_t kArrow = 10 * kInstanceIdFactor;
constexpr std::uint16_t kStopLine = 21 * kInstanceIdFactor;

class AbsurdMasksTest : public ::testing::Test {
 protected:
  FrameObservations Extract(const cv::Mat& mask) const {
    return ExtractObservations(mask, classes_, ipm_, error_model_, options_);
  }

  // A mask with one ground rectangle (base_link) of `value`.
  static cv::Mat GroundMask(double x0, double x1, double y0, double y1, std::uint16_t value) {
    cv::Mat mask = EmptyMask();
    FillGround(Rect(x0, x1, y0, y1), PoseAt(0.0), value, &mask);
    return mask;
  }

  static cv::Mat EmptyMask() { return cv::Mat::zeros(720, 1280, CV_16UC1); }

  // Nothing extracted at all.
  static void ExpectNothing(const FrameObservations& obs) {
    EXPECT_TRUE(obs.markings.empty());
    EXPECT_TRUE(obs.lanes.empty());
  }

  ClassTable classes_ = ShippedClasses();
  Ipm ipm_{PinholeCamera(test::TestCamera()), test::TestExtrinsic(), 100.0};
  IpmErrorModel error_model_;
  ExtractionOptions options_;
};

TEST_F(AbsurdMasksTest, PlausibleMaskIsUntouched) {
  // A real line, an arrow and a stop line across three lanes: nothing implausible.
  cv::Mat mask = GroundMask(4.0, 30.0, 1.7, 1.85, kSolidLane + 1);
  FillGround(Rect(10.0, 15.0, -0.6, 0.6), PoseAt(0.0), kArrow + 1, &mask);
  FillGround(Rect(18.0, 18.4, -5.0, 5.0), PoseAt(0.0), kStopLine + 1, &mask);
  const FrameObservations obs = Extract(mask);
  EXPECT_EQ(obs.lanes.size(), 1u);
  EXPECT_EQ(obs.markings.size(), 2u);
  EXPECT_EQ(obs.counters.lane_runs_too_wide, 0u);
  EXPECT_EQ(obs.counters.dropped_oversized, 0u);
  EXPECT_EQ(obs.counters.frames_too_much_coverage + obs.counters.frames_too_many_instances, 0u);
}

TEST_F(AbsurdMasksTest, WholeImageLaneInstance) {
  const cv::Mat mask(720, 1280, CV_16UC1, cv::Scalar(kSolidLane + 1));
  const FrameObservations obs = Extract(mask);
  ExpectNothing(obs);
  EXPECT_EQ(obs.counters.frames_too_much_coverage, 1u);
  EXPECT_EQ(obs.counters.dropped_absurd_frame, 1u);
  // Without the frame check, the lane check drops it: every row's run is meters wide.
  options_.max_coverage = 1.0;
  const FrameObservations lane = Extract(mask);
  ExpectNothing(lane);
  EXPECT_EQ(lane.counters.dropped_wide_lane, 1u);
  EXPECT_GT(lane.counters.lane_runs_too_wide, 50u);
}

TEST_F(AbsurdMasksTest, LaneDoublingBackIsDropped) {
  // One instance running out along y = 1.8 m, turning at 30 m and coming back along y = 3.0 m
  // (a U): most rows cross it twice, and which arm is the line is unknown.
  cv::Mat mask = GroundMask(4.0, 30.0, 1.725, 1.875, kSolidLane + 1);
  FillGround(Rect(29.7, 30.0, 1.725, 3.075), PoseAt(0.0), kSolidLane + 1, &mask);
  FillGround(Rect(4.0, 30.0, 2.925, 3.075), PoseAt(0.0), kSolidLane + 1, &mask);
  const FrameObservations obs = Extract(mask);
  ExpectNothing(obs);
  EXPECT_EQ(obs.counters.dropped_doubled_lane, 1u);
  EXPECT_GT(obs.counters.lane_rows_doubled, 20u);
  // A short second arm (a fork's first meters): kept, its rows counted.
  cv::Mat fork = GroundMask(4.0, 30.0, 1.725, 1.875, kSolidLane + 1);
  FillGround(Rect(27.0, 30.0, 2.1, 2.25), PoseAt(0.0), kSolidLane + 1, &fork);
  const FrameObservations kept = Extract(fork);
  ASSERT_EQ(kept.lanes.size(), 1u);
  EXPECT_EQ(kept.counters.dropped_doubled_lane, 0u);
  EXPECT_GT(kept.counters.lane_rows_doubled, 0u);
  // A plain line has no doubled row.
  EXPECT_EQ(Extract(GroundMask(4.0, 30.0, 1.725, 1.875, kSolidLane + 1)).counters.lane_rows_doubled,
            0u);
}

TEST_F(AbsurdMasksTest, LaneCoveringHalfTheImage) {
  // The left half of the image as one lane instance: under the frame's coverage bound, but
  // every row's run is meters wide on the ground.
  cv::Mat mask = EmptyMask();
  mask(cv::Rect(0, 0, 640, 720)).setTo(cv::Scalar(kSolidLane + 1));
  const FrameObservations obs = Extract(mask);
  ExpectNothing(obs);
  EXPECT_EQ(obs.counters.frames_too_much_coverage, 0u);
  EXPECT_EQ(obs.counters.dropped_wide_lane, 1u);
}

TEST_F(AbsurdMasksTest, WholeImageMarking) {
  const cv::Mat mask(720, 1280, CV_16UC1, cv::Scalar(kArrow + 1));
  const FrameObservations obs = Extract(mask);
  ExpectNothing(obs);
  // Cut by the border on every side and by the horizon: no observation, counted once (its
  // part below the horizon is centred beyond the marking range).
  EXPECT_EQ(
      obs.counters.dropped_range + obs.counters.dropped_oversized + obs.counters.dropped_border,
      1u);
}

TEST_F(AbsurdMasksTest, MarkingCoveringMostOfTheRoadDropsTheFrame) {
  // Inside the image (no border contact) but painting most of the road.
  cv::Mat mask = EmptyMask();
  mask(cv::Rect(5, 300, 1270, 415)).setTo(kArrow + 1);
  mask(cv::Rect(600, 500, 20, 20)).setTo(kArrow + 2);
  const FrameObservations obs = Extract(mask);
  ExpectNothing(obs);
  EXPECT_EQ(obs.counters.frames_too_much_coverage, 1u);
  EXPECT_EQ(obs.counters.dropped_absurd_frame, 2u);
}

TEST_F(AbsurdMasksTest, WideLaneBlob) {
  // A "lane" 3 m wide: every run is 2.4 m wider than a line.
  const FrameObservations obs = Extract(GroundMask(5.0, 30.0, -1.5, 1.5, kSolidLane + 1));
  ExpectNothing(obs);
  EXPECT_EQ(obs.counters.dropped_wide_lane, 1u);
  EXPECT_GT(obs.counters.lane_runs_too_wide, 20u);
  EXPECT_EQ(obs.counters.frames_too_much_coverage, 0u);
}

TEST_F(AbsurdMasksTest, WideRunsOfAPlausibleLaneGiveNoPoints) {
  // A real line whose near part the network smeared over 2 m: those runs give no point,
  // the line survives.
  cv::Mat mask = GroundMask(4.0, 30.0, 1.7, 1.85, kSolidLane + 1);
  FillGround(Rect(4.0, 5.5, 0.8, 2.8), PoseAt(0.0), kSolidLane + 1, &mask);
  const FrameObservations obs = Extract(mask);
  ASSERT_EQ(obs.lanes.size(), 1u);
  EXPECT_GT(obs.counters.lane_runs_too_wide, 0u);
  for (const LanePoint& p : obs.lanes[0].points) EXPECT_NEAR(p.p_base.y(), 1.775, 0.1);
}

TEST_F(AbsurdMasksTest, OversizedMarkings) {
  // An arrow 14 m long (the class allows 10) and one 5 m wide (4): both oversized.
  cv::Mat mask = GroundMask(6.0, 20.0, -0.6, 0.6, kArrow + 1);
  FillGround(Rect(12.0, 16.0, 1.0, 6.0), PoseAt(0.0), kArrow + 2, &mask);
  const FrameObservations obs = Extract(mask);
  ExpectNothing(obs);
  EXPECT_EQ(obs.counters.dropped_oversized, 2u);
  // The same 14 m as a stop line across the road: within its class's 20 m.
  const FrameObservations stop_line = Extract(GroundMask(15.0, 15.4, -7.0, 7.0, kStopLine + 1));
  EXPECT_EQ(stop_line.markings.size(), 1u);
  EXPECT_EQ(stop_line.counters.dropped_oversized, 0u);
}

TEST_F(AbsurdMasksTest, OnePixelSlivers) {
  // A lane one row high across the image: its only run is meters wide.
  cv::Mat lane_mask = EmptyMask();
  lane_mask.row(560).setTo(kSolidLane + 1);
  const FrameObservations lane = Extract(lane_mask);
  ExpectNothing(lane);
  EXPECT_EQ(lane.counters.dropped_wide_lane, 1u);
  // A marking one column wide down the road: no area on the ground.
  cv::Mat marking_mask = EmptyMask();
  marking_mask(cv::Rect(640, 420, 1, 290)).setTo(kArrow + 1);
  const FrameObservations marking = Extract(marking_mask);
  ExpectNothing(marking);
  EXPECT_EQ(marking.counters.dropped_degenerate, 1u);
}

TEST_F(AbsurdMasksTest, OutlineLeavingTheImageOnThreeSides) {
  // The bottom 160 rows, cut by the left, right and bottom sides.
  cv::Mat lane_mask = EmptyMask();
  lane_mask(cv::Rect(0, 560, 1280, 160)).setTo(kSolidLane + 1);
  const FrameObservations lane = Extract(lane_mask);
  ExpectNothing(lane);
  EXPECT_EQ(lane.counters.dropped_wide_lane, 1u);  // cut runs are at least this wide
  EXPECT_EQ(lane.counters.frames_too_much_coverage, 0u);
  cv::Mat marking_mask = EmptyMask();
  marking_mask(cv::Rect(0, 560, 1280, 160)).setTo(kArrow + 1);
  const FrameObservations marking = Extract(marking_mask);
  ExpectNothing(marking);
  EXPECT_EQ(marking.counters.dropped_border, 1u);
}

// `n` square instances of `side` px (the values of `values`) in a grid below the horizon,
// 2 px apart, away from the image border.
cv::Mat GridOfInstances(const std::vector<std::uint16_t>& values, int side) {
  cv::Mat mask = cv::Mat::zeros(720, 1280, CV_16UC1);
  const int pitch = side + 2, per_row = (1280 - 20) / pitch;
  for (std::size_t i = 0; i < values.size(); ++i) {
    const int col = 10 + static_cast<int>(i % per_row) * pitch;
    const int row = 400 + static_cast<int>(i / per_row) * pitch;
    mask(cv::Rect(col, row, side, side)).setTo(values[i]);
  }
  return mask;
}

TEST_F(AbsurdMasksTest, SixHundredPlausibleInstances) {
  // 600 arrow-sized blobs (14x14 px = 196 px, above the 150 px minimum).
  std::vector<std::uint16_t> values;
  for (int i = 0; i < 600; ++i) values.push_back(static_cast<std::uint16_t>(kArrow + i));
  const FrameObservations obs = Extract(GridOfInstances(values, 14));
  ExpectNothing(obs);
  EXPECT_EQ(obs.counters.instances_seen, 600u);
  EXPECT_EQ(obs.counters.frames_too_many_instances, 1u);
  EXPECT_EQ(obs.counters.dropped_absurd_frame, 600u);
  EXPECT_EQ(obs.counters.dropped_instance_limit, 0u);
}

TEST_F(AbsurdMasksTest, TenThousandTinyInstances) {
  const std::vector<std::uint16_t> values = KnownValues(classes_, 10000);
  ASSERT_EQ(values.size(), 10000u);
  const cv::Mat mask = GridOfInstances(values, 2);
  const FrameObservations obs = Extract(mask);
  ExpectNothing(obs);
  EXPECT_EQ(obs.counters.dropped_tiny, 10000u);
  // Were they large enough to pass the size minimum, there would still be far too many.
  options_.min_marking_pixels = options_.min_lane_pixels = 4;
  const FrameObservations candidates = Extract(mask);
  ExpectNothing(candidates);
  EXPECT_EQ(candidates.counters.frames_too_many_instances, 1u);
  EXPECT_EQ(candidates.counters.dropped_absurd_frame, 10000u);
}

}  // namespace
}  // namespace ipm_road_mapper
