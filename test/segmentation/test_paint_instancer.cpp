// The ground-plane instancer on rendered paint: lines, dashes, hatching, blobs, no paint.
#include <gtest/gtest.h>

#include <map>
#include <random>

#include "ipm_road_mapper/segmentation/paint_instancer.h"
#include "segmentation/paint_scene.h"

namespace ipm_road_mapper {
namespace {

using segmentation::PaintClass;
using segmentation::SegmentedFrame;
using test::Stripe;

SegmentedFrame Segment(const std::vector<Stripe>& stripes) {
  segmentation::PaintInstancer instancer{segmentation::InstanceOptions{}};
  return instancer.Run(test::RenderPaint(stripes), test::PaintCamera(), test::PaintMount());
}

std::map<PaintClass, int> CountByClass(const SegmentedFrame& frame) {
  std::map<PaintClass, int> count;
  for (const auto& instance : frame.instances) ++count[instance.paint_class];
  return count;
}

// "lane_solid 1, hatched_area 1" for failure messages.
std::string Describe(const SegmentedFrame& frame) {
  std::string text;
  for (const auto& [paint_class, n] : CountByClass(frame)) {
    text += std::string(segmentation::ToString(paint_class)) + " " + std::to_string(n) + ", ";
  }
  const auto& d = frame.counters.dropped;
  return text + "dropped: blobs " + std::to_string(d.blobs) + ", short " +
         std::to_string(d.short_lines) + ", wide " + std::to_string(d.wide_strokes) +
         ", low confidence " + std::to_string(d.low_confidence);
}

TEST(PaintInstancer, NoPaintGivesAnEmptyMask) {
  const SegmentedFrame frame = Segment({});
  EXPECT_TRUE(frame.instances.empty());
  EXPECT_EQ(cv::countNonZero(frame.mask), 0);
}

TEST(PaintInstancer, SpeckleGivesNoInstance) {
  cv::Mat paint(720, 1280, CV_32F, cv::Scalar(0.0));
  std::mt19937 random(7);
  std::uniform_int_distribution<int> u(0, 1279), v(380, 719);
  for (int i = 0; i < 9000; ++i) paint.at<float>(v(random), u(random)) = 0.9f;  // ~3 %
  segmentation::PaintInstancer instancer{segmentation::InstanceOptions{}};
  const SegmentedFrame frame = instancer.Run(paint, test::PaintCamera(), test::PaintMount());
  EXPECT_TRUE(frame.instances.empty()) << frame.instances.size() << " instances";
  EXPECT_GT(frame.counters.speckle, 0);
}

TEST(PaintInstancer, SolidAndDashedLinesAreOneInstanceEach) {
  std::vector<Stripe> stripes = test::DashedLine(1.8, 6.0, 4);
  stripes.push_back(test::SolidLine(-1.8, 5.0, 40.0));
  const SegmentedFrame frame = Segment(stripes);
  std::map<PaintClass, int> count = CountByClass(frame);
  SCOPED_TRACE(Describe(frame));
  EXPECT_EQ(count[PaintClass::kLaneSolid], 1);
  EXPECT_EQ(count[PaintClass::kLaneDashed], 1);  // every dash in one instance
  EXPECT_EQ(frame.instances.size(), 2u);
  for (const auto& instance : frame.instances) {
    EXPECT_GT(instance.confidence, 0.5);
    EXPECT_LE(instance.confidence, 1.0);
    EXPECT_EQ(instance.value / 1000, instance.paint_class == PaintClass::kLaneSolid ? 1 : 2);
  }
}

TEST(PaintInstancer, HatchingIsOneAreaAndNoLane) {
  std::vector<Stripe> stripes = test::Hatching(10.0, 5.0, 8, M_PI / 4.0);
  stripes.push_back(test::SolidLine(-1.8, 5.0, 40.0));
  const SegmentedFrame frame = Segment(stripes);
  std::map<PaintClass, int> count = CountByClass(frame);
  SCOPED_TRACE(Describe(frame));
  EXPECT_EQ(count[PaintClass::kHatchedArea], 1);
  EXPECT_EQ(count[PaintClass::kLaneSolid], 1);
  EXPECT_EQ(count[PaintClass::kLaneDashed], 0);
  EXPECT_EQ(count[PaintClass::kCrossingStripe], 0);
}

TEST(PaintInstancer, ChevronsMergedWithTheirLineAreSplitFromIt) {
  // Stripes at 45 deg whose ends touch the edge line at y = 2: one blob of paint in the
  // image, split on the ground into the line and the hatching.
  std::vector<Stripe> stripes;
  for (int i = 0; i < 7; ++i) {
    const double x = 10.0 + 2.0 * i;
    stripes.push_back({{x + 1.06, 2.0 + 1.06}, M_PI / 4.0, 3.0, 0.4});
  }
  stripes.push_back(test::SolidLine(2.0, 5.0, 40.0));
  const SegmentedFrame frame = Segment(stripes);
  std::map<PaintClass, int> count = CountByClass(frame);
  SCOPED_TRACE(Describe(frame));
  EXPECT_EQ(count[PaintClass::kHatchedArea], 1);
  EXPECT_EQ(count[PaintClass::kLaneSolid], 1);
  EXPECT_EQ(count[PaintClass::kLaneDashed], 0);
}

TEST(PaintInstancer, CrossingStripesAreStripesNotLanes) {
  // Zebra stripes along the travel, 0.5 m wide, 1 m apart across the road.
  std::vector<Stripe> stripes;
  for (int i = 0; i < 7; ++i) stripes.push_back({{12.0, -3.0 + 1.0 * i}, 0.0, 3.0, 0.5});
  const SegmentedFrame frame = Segment(stripes);
  std::map<PaintClass, int> count = CountByClass(frame);
  SCOPED_TRACE(Describe(frame));
  EXPECT_GE(count[PaintClass::kCrossingStripe], 5);
  EXPECT_EQ(count[PaintClass::kLaneSolid] + count[PaintClass::kLaneDashed], 0);
  EXPECT_EQ(count[PaintClass::kHatchedArea], 0);
}

TEST(PaintInstancer, ABlobIsNotMapped) {
  // A 1.5 x 1.2 m blob beside the road (a shadow, a curb): no class fits.
  const SegmentedFrame frame = Segment({{{12.0, -5.0}, 0.3, 1.5, 1.2}});
  EXPECT_TRUE(frame.instances.empty());
  EXPECT_GT(frame.counters.dropped.blobs, 0);
}

}  // namespace
}  // namespace ipm_road_mapper
