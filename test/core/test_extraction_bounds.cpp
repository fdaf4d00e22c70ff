// Instance extraction on bad and huge masks (instance_extraction.h): mask validation,
// unusable and non-continuous masks, an all-foreground mask and ten thousand instances
// bounded in time with every instance accounted for, the instance limit, a realistic frame's
// timing; and the extraction options and counters.
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
#include "common/options_test_utils.h"
#include "ipm_road_mapper/core/frontend/instance_extraction.h"

namespace ipm_road_mapper {
namespace {

TEST(ValidateMaskTest, RejectsWrongTypeSizeAndEmpty) {
  EXPECT_EQ(ValidateMask(EmptyMask(), kTestWidth, kTestHeight), "");
  const std::string wrong_8u =
      ValidateMask(cv::Mat(kTestHeight, kTestWidth, CV_8UC1), kTestWidth, kTestHeight);
  EXPECT_NE(wrong_8u.find("8UC1"), std::string::npos) << wrong_8u;
  EXPECT_NE(wrong_8u.find("16UC1"), std::string::npos) << wrong_8u;
  const std::string wrong_3c =
      ValidateMask(cv::Mat(kTestHeight, kTestWidth, CV_16UC3), kTestWidth, kTestHeight);
  EXPECT_NE(wrong_3c.find("16UC3"), std::string::npos) << wrong_3c;
  EXPECT_NE(
      ValidateMask(cv::Mat(kTestHeight, kTestWidth, CV_32F), kTestWidth, kTestHeight).find("32FC1"),
      std::string::npos);
  const std::string wrong_size = ValidateMask(cv::Mat(480, 640, CV_16UC1), kTestWidth, kTestHeight);
  EXPECT_EQ(wrong_size, "mask is 640x480, camera is 1280x720");
  const std::string empty = ValidateMask(cv::Mat(), kTestWidth, kTestHeight);
  EXPECT_NE(empty.find("empty"), std::string::npos) << empty;
  for (const std::string& reason : {wrong_8u, wrong_3c, wrong_size, empty}) {
    EXPECT_EQ(reason.find('\n'), std::string::npos);
  }
}

TEST_F(InstanceExtractionTest, UnusableMaskGivesNothingWithoutCrash) {
  EXPECT_EQ(Extract(cv::Mat()).counters.instances_seen, 0u);
  EXPECT_EQ(
      Extract(cv::Mat(kTestHeight, kTestWidth, CV_8UC1, cv::Scalar(200))).counters.instances_seen,
      0u);
}

TEST_F(InstanceExtractionTest, NonContinuousMaskView) {
  // A view into a wider buffer (rows not contiguous) must give the same result.
  cv::Mat wide(kTestHeight, kTestWidth + 64, CV_16UC1, cv::Scalar(0));
  cv::Mat view = wide(cv::Rect(32, 0, kTestWidth, kTestHeight));
  RenderGroundRectangle(ipm_, {10.0, 0.0}, 2.0, 0.5, 20 * kDeg, kArrow, &view);
  ASSERT_FALSE(view.isContinuous());
  const FrameObservations a = Extract(view);
  const FrameObservations b = Extract(view.clone());
  ASSERT_EQ(a.markings.size(), 1u);
  ASSERT_EQ(b.markings.size(), 1u);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(a.markings[0].corners_uv[i], b.markings[0].corners_uv[i]);
}

// Sum of every outcome of an instance: each seen instance is accounted for exactly once.
std::uint64_t Accounted(const FrameObservations& obs) {
  const ExtractionCounters& c = obs.counters;
  return obs.markings.size() + obs.lanes.size() + c.dropped_unknown_class + c.dropped_tiny +
         c.dropped_border + c.dropped_range + c.dropped_degenerate + c.dropped_instance_limit +
         c.dropped_oversized + c.dropped_wide_lane + c.dropped_absurd_frame;
}

TEST_F(InstanceExtractionTest, AllForegroundMaskIsBounded) {
  // Every pixel one lane instance: handled like a (very wide) lane, no crash.
  const auto start = std::chrono::steady_clock::now();
  const FrameObservations lane =
      Extract(cv::Mat(kTestHeight, kTestWidth, CV_16UC1, cv::Scalar(kSolidLane + 1)));
  const double lane_ms = MsSince(start);
  EXPECT_EQ(lane.counters.instances_seen, 1u);
  EXPECT_LE(lane.lanes.size(), 1u);
  // Every pixel one marking instance: cut by the border everywhere and the horizon, its
  // part in range centred beyond max_marking_range_m: dropped, counted once.
  const FrameObservations marking =
      Extract(cv::Mat(kTestHeight, kTestWidth, CV_16UC1, cv::Scalar(kArrow + 1)));
  EXPECT_EQ(marking.counters.instances_seen, 1u);
  EXPECT_EQ(Accounted(marking), 1u);
  EXPECT_TRUE(marking.markings.empty());
  std::cout << "[ info ] all-foreground lane mask: " << lane_ms << " ms\n";
  ExpectFasterThan(lane_ms, 200.0);
}

// The n-th distinct instance value: classes 1..65 in turn, instance indices 0..999,
// skipping values above 65535.
std::vector<std::uint16_t> DistinctValues(int n) {
  std::vector<std::uint16_t> values;
  for (int index = 0; static_cast<int>(values.size()) < n && index < kInstanceIdFactor; ++index) {
    for (int class_id = 1; class_id <= kMaxClassId && static_cast<int>(values.size()) < n;
         ++class_id) {
      const int value = class_id * kInstanceIdFactor + index;
      if (value <= 65535) values.push_back(static_cast<std::uint16_t>(value));
    }
  }
  return values;
}

TEST_F(InstanceExtractionTest, TenThousandInstancesInTilesAreBounded) {
  options_.min_marking_pixels = 20;  // let the small tiles through to the instance limit
  options_.min_lane_pixels = 20;
  options_.min_lane_points = 2;
  options_.max_plausible_instances = 100000;  // this test is about the instance limit
  const std::vector<std::uint16_t> values = DistinctValues(10000);
  ASSERT_EQ(values.size(), 10000u);
  cv::Mat mask = EmptyMask();
  const int tile = 8, tiles_per_row = kTestWidth / tile;
  for (int i = 0; i < 10000; ++i) {
    mask(cv::Rect((i % tiles_per_row) * tile, (i / tiles_per_row) * tile, tile, tile))
        .setTo(values[i]);
  }
  const auto start = std::chrono::steady_clock::now();
  const FrameObservations obs = Extract(mask);
  const double ms = MsSince(start);
  std::cout << "[ info ] 10,000 tiled instances: " << ms << " ms, "
            << obs.counters.dropped_instance_limit << " over the limit\n";
  EXPECT_EQ(obs.counters.instances_seen, 10000u);
  EXPECT_GT(obs.counters.dropped_instance_limit, 0u);
  const std::uint64_t processed = obs.markings.size() + obs.lanes.size() +
                                  obs.counters.dropped_range + obs.counters.dropped_degenerate;
  EXPECT_EQ(processed, static_cast<std::uint64_t>(options_.max_instances_per_frame));
  EXPECT_EQ(Accounted(obs), 10000u);
  ExpectFasterThan(ms, 200.0);
}

TEST_F(InstanceExtractionTest, TenThousandScatteredInstancesAreBounded) {
  // Every pixel a different instance than its neighbor, each instance spread over the
  // whole image (bounding boxes all image-sized): the worst case for per-ROI work.
  const std::vector<std::uint16_t> values = DistinctValues(10000);
  cv::Mat mask = EmptyMask();
  for (int row = 0; row < kTestHeight; ++row) {
    for (int col = 0; col < kTestWidth; ++col) {
      mask.at<std::uint16_t>(row, col) = values[(row * 7919 + col) % values.size()];
    }
  }
  options_.min_marking_pixels = 20;
  options_.min_lane_pixels = 20;
  options_.max_plausible_instances = 100000;  // the geometry's worst case, not the frame check
  const auto start = std::chrono::steady_clock::now();
  const FrameObservations obs = Extract(mask);
  const double ms = MsSince(start);
  std::cout << "[ info ] 10,000 scattered instances: " << ms << " ms\n";
  EXPECT_EQ(obs.counters.instances_seen, 10000u);
  EXPECT_EQ(Accounted(obs), 10000u);
  EXPECT_LE(obs.markings.size() + obs.lanes.size(),
            static_cast<std::size_t>(options_.max_instances_per_frame));
  ExpectFasterThan(ms, 400.0);  // the adversarial case: 921,600 one-pixel runs
}

TEST_F(InstanceExtractionTest, InstanceLimitKeepsTheLargest) {
  options_.max_instances_per_frame = 1;
  cv::Mat mask = EmptyMask();
  RenderGroundRectangle(ipm_, {12.0, -2.0}, 2.0, 0.5, 0.0, kArrow + 1, &mask);
  RenderGroundRectangle(ipm_, {9.0, 1.5}, 3.0, 1.0, 0.0, kArrow + 2, &mask);
  const FrameObservations obs = Extract(mask);
  ASSERT_EQ(obs.markings.size(), 1u);
  EXPECT_EQ(obs.markings[0].instance_value, kArrow + 2);
  EXPECT_EQ(obs.counters.dropped_instance_limit, 1u);
}

// A realistic frame: four lanes (two dashed) and a few markings.
cv::Mat RealisticMask(const Ipm& ipm) {
  cv::Mat mask = EmptyMask();
  RenderLaneStrip(ipm, 5.4, 3.5, 45.0, 0.15, kSolidLane + 0, &mask);
  for (double x = 4.0; x < 45.0; x += 9.0) {
    RenderLaneStrip(ipm, 1.8, x, x + 3.0, 0.15, kDashedLane + 1, &mask);
    RenderLaneStrip(ipm, -1.8, x + 2.0, x + 5.0, 0.15, kDashedLane + 2, &mask);
  }
  RenderLaneStrip(ipm, -5.4, 3.5, 45.0, 0.15, kSolidLane + 3, &mask);
  RenderGroundRectangle(ipm, {8.0, 0.0}, 3.0, 0.6, 0.0, kArrow + 0, &mask);
  RenderGroundRectangle(ipm, {15.0, -3.6}, 3.0, 0.6, 0.05, kArrow + 1, &mask);
  RenderGroundRectangle(ipm, {20.0, 3.6}, 0.4, 3.4, 0.0, kStopLine + 0, &mask);
  RenderGroundRectangle(ipm, {22.0, 0.0}, 2.5, 1.0, 0.0, 23 * kInstanceIdFactor, &mask);
  return mask;
}

TEST_F(InstanceExtractionTest, RealisticFrameTiming) {
  const cv::Mat mask = RealisticMask(ipm_);
  FrameObservations obs = Extract(mask);  // warm-up
  EXPECT_EQ(obs.lanes.size(), 4u);
  EXPECT_EQ(obs.markings.size(), 4u);
  EXPECT_EQ(Accounted(obs), obs.counters.instances_seen);
  constexpr int kRuns = 50;
  const auto start = std::chrono::steady_clock::now();
  std::size_t points = 0;
  for (int run = 0; run < kRuns; ++run) {
    obs = Extract(mask);
    for (const LaneObservation& lane : obs.lanes) points += lane.points.size();
  }
  const double ms = MsSince(start) / kRuns;
  std::cout << "[ info ] realistic 1280x720 frame (4 lanes, 4 markings, " << points / kRuns
            << " lane points): " << ms << " ms per extraction (mean of " << kRuns << ")\n";
  ExpectFasterThan(ms, 200.0);
}

TEST(ExtractionOptionsTest, LoadsValuesAndRejectsUnknownKeys) {
  OptionsReader root(YAML::Load("extraction: {lane_row_step: 6, max_marking_range_m: 30.0}"), "");
  const ExtractionOptions o = LoadExtractionOptions(root.Child("extraction"));
  EXPECT_EQ(o.lane_row_step, 6);
  EXPECT_EQ(o.max_marking_range_m, 30.0);
  EXPECT_EQ(o.min_marking_pixels, ExtractionOptions().min_marking_pixels);

  OptionsReader typo(YAML::Load("extraction: {lane_row_stepp: 6}"), "");
  const std::string typo_error = ErrorOf([&] { LoadExtractionOptions(typo.Child("extraction")); });
  EXPECT_NE(typo_error.find("extraction.lane_row_stepp"), std::string::npos) << typo_error;
  OptionsReader bad(YAML::Load("extraction: {lane_row_step: 0}"), "");
  const std::string bad_error = ErrorOf([&] { LoadExtractionOptions(bad.Child("extraction")); });
  EXPECT_NE(bad_error.find("extraction.lane_row_step"), std::string::npos) << bad_error;
}

TEST(ExtractionCountersTest, AddSumsEveryCounter) {
  ExtractionCounters a, b;
  a.instances_seen = 1;
  a.dropped_unknown_class = 2;
  a.dropped_tiny = 3;
  a.dropped_border = 4;
  a.dropped_range = 5;
  a.dropped_degenerate = 6;
  a.dropped_instance_limit = 7;
  a.dropped_oversized = 8;
  a.dropped_wide_lane = 9;
  a.dropped_absurd_frame = 10;
  a.lane_runs_too_wide = 11;
  a.frames_too_many_instances = 12;
  a.frames_too_much_coverage = 13;
  b.Add(a);
  b.Add(a);
  EXPECT_EQ(b.instances_seen, 2u);
  EXPECT_EQ(b.dropped_unknown_class, 4u);
  EXPECT_EQ(b.dropped_tiny, 6u);
  EXPECT_EQ(b.dropped_border, 8u);
  EXPECT_EQ(b.dropped_range, 10u);
  EXPECT_EQ(b.dropped_degenerate, 12u);
  EXPECT_EQ(b.dropped_instance_limit, 14u);
  EXPECT_EQ(b.dropped_oversized, 16u);
  EXPECT_EQ(b.dropped_wide_lane, 18u);
  EXPECT_EQ(b.dropped_absurd_frame, 20u);
  EXPECT_EQ(b.lane_runs_too_wide, 22u);
  EXPECT_EQ(b.frames_too_many_instances, 24u);
  EXPECT_EQ(b.frames_too_much_coverage, 26u);
}

}  // namespace
}  // namespace ipm_road_mapper
