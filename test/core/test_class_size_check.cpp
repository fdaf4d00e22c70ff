// The class-table check (class_size_check.h): the extraction counts, per marking class, the
// views it sized and those it dropped as oversized; a class most of whose views are oversized
// is named, so a user who maps masks with another network's table is told so.
#include <gtest/gtest.h>

#include <cstdint>
#include <opencv2/core.hpp>

#include "common/class_values.h"
#include "common/road_scene.h"
#include "ipm_road_mapper/core/frontend/class_size_check.h"
#include "ipm_road_mapper/core/frontend/instance_extraction.h"

namespace ipm_road_mapper {
namespace {

using test::FillGround;
using test::PoseAt;
using test::Rect;

// config/classes.yaml: 1 lane_white_solid, 10 arrow_straight (at most 10 x 4 m), 21 stop_line.
constexpr int kLaneClass = 1;
constexpr int kArrowClass = 10;
constexpr int kStopLineClass = 21;
constexpr std::uint16_t kArrow = kArrowClass * kInstanceIdFactor;
constexpr std::uint16_t kStopLine = kStopLineClass * kInstanceIdFactor;

class ClassSizeCheckTest : public ::testing::Test {
 protected:
  FrameObservations Extract(const cv::Mat& mask) const {
    return ExtractObservations(mask, classes_, ipm_, error_model_, options_);
  }
  ClassTable classes_ = ShippedClasses();
  Ipm ipm_{PinholeCamera(test::TestCamera()), test::TestExtrinsic(), 100.0};
  IpmErrorModel error_model_;
  ExtractionOptions options_;
};

TEST_F(ClassSizeCheckTest, ExtractionCountsSizedAndOversizedViewsPerClass) {
  // A crossing 14 m across the road under the arrow's id: oversized. A plausible arrow and a
  // stop line: sized, kept.
  cv::Mat mask = cv::Mat::zeros(720, 1280, CV_16UC1);
  FillGround(Rect(16.0, 19.0, -7.0, 7.0), PoseAt(0.0), kArrow + 1, &mask);
  FillGround(Rect(8.0, 13.0, -0.6, 0.6), PoseAt(0.0), kArrow + 2, &mask);
  FillGround(Rect(22.0, 22.4, -3.0, 3.0), PoseAt(0.0), kStopLine + 1, &mask);
  const FrameObservations obs = Extract(mask);
  EXPECT_EQ(obs.markings.size(), 2u);
  EXPECT_EQ(obs.counters.dropped_oversized, 1u);
  EXPECT_EQ(obs.counters.markings_sized_by_class[kArrowClass], 2u);
  EXPECT_EQ(obs.counters.markings_oversized_by_class[kArrowClass], 1u);
  EXPECT_EQ(obs.counters.markings_sized_by_class[kStopLineClass], 1u);
  EXPECT_EQ(obs.counters.markings_oversized_by_class[kStopLineClass], 0u);
  // Summed over frames like every counter.
  ExtractionCounters total;
  total.Add(obs.counters);
  total.Add(obs.counters);
  EXPECT_EQ(total.markings_sized_by_class[kArrowClass], 4u);
  EXPECT_EQ(total.markings_oversized_by_class[kArrowClass], 2u);
}

TEST_F(ClassSizeCheckTest, NamesAClassMostOfWhoseViewsAreOversized) {
  ExtractionCounters c;
  c.markings_sized_by_class[kArrowClass] = 30;
  c.markings_oversized_by_class[kArrowClass] = 16;
  c.markings_sized_by_class[kStopLineClass] = 40;
  c.markings_oversized_by_class[kStopLineClass] = 20;  // half: not more than half
  const std::vector<OversizedClass> suspects = MostlyOversizedClasses(c, classes_);
  ASSERT_EQ(suspects.size(), 1u);
  EXPECT_EQ(suspects[0].class_id, kArrowClass);
  EXPECT_EQ(suspects[0].name, "arrow_straight");
  EXPECT_EQ(suspects[0].oversized, 16u);
  EXPECT_EQ(suspects[0].sized, 30u);
  const std::string text = Describe(suspects[0]);
  EXPECT_NE(text.find("class 10 'arrow_straight'"), std::string::npos) << text;
  EXPECT_NE(text.find("16 of 30 views"), std::string::npos) << text;
  EXPECT_NE(text.find("10.0 x 4.0 m"), std::string::npos) << text;
}

TEST_F(ClassSizeCheckTest, JudgesNoClassOnFewViewsAndNoLaneClass) {
  ExtractionCounters c;
  c.markings_sized_by_class[kArrowClass] = kMinSizedViewsToJudge - 1;
  c.markings_oversized_by_class[kArrowClass] = kMinSizedViewsToJudge - 1;
  c.markings_sized_by_class[kLaneClass] = 100;  // not a marking class: never counted so
  c.markings_oversized_by_class[kLaneClass] = 100;
  EXPECT_TRUE(MostlyOversizedClasses(c, classes_).empty());
  c.markings_sized_by_class[kArrowClass] = kMinSizedViewsToJudge;
  c.markings_oversized_by_class[kArrowClass] = kMinSizedViewsToJudge;
  EXPECT_EQ(MostlyOversizedClasses(c, classes_).size(), 1u);
}

TEST_F(ClassSizeCheckTest, APlausibleDriveNamesNothing) {
  ExtractionCounters c;
  cv::Mat mask = cv::Mat::zeros(720, 1280, CV_16UC1);
  FillGround(Rect(8.0, 13.0, -0.6, 0.6), PoseAt(0.0), kArrow + 1, &mask);
  const FrameObservations obs = Extract(mask);
  for (int i = 0; i < 50; ++i) c.Add(obs.counters);
  EXPECT_EQ(c.markings_sized_by_class[kArrowClass], 50u);
  EXPECT_TRUE(MostlyOversizedClasses(c, classes_).empty());
}

}  // namespace
}  // namespace ipm_road_mapper
