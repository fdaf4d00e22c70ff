// The mask's sanity stage before extraction: area classes out, lane instances that hold
// several lines split, dashes of one line kept together, class flicker resolved by evidence.
#include <gtest/gtest.h>

#include <set>

#include "ipm_road_mapper/core/frontend/mask_sanity.h"
#include "segmentation/paint_scene.h"

namespace ipm_road_mapper {
namespace {

using test::Stripe;

// A 16UC1 mask of the paint scene's camera: each stripe painted with its value.
cv::Mat RenderMask(const std::vector<std::pair<Stripe, std::uint16_t>>& stripes) {
  const PinholeCamera camera = test::PaintCamera();
  const Ipm ipm(camera, test::PaintMount(), 1e9);
  cv::Mat mask = cv::Mat::zeros(camera.height(), camera.width(), CV_16UC1);
  for (int v = 0; v < mask.rows; ++v) {
    for (int u = 0; u < mask.cols; ++u) {
      Eigen::Vector3d p;
      if (ipm.PixelToGround(Eigen::Vector2d(u, v), &p) != IpmStatus::kOk) continue;
      for (const auto& [stripe, value] : stripes) {
        if (stripe.Contains(p.head<2>())) mask.at<std::uint16_t>(v, u) = value;
      }
    }
  }
  return mask;
}

std::set<std::uint16_t> Values(const cv::Mat& mask) {
  std::set<std::uint16_t> values;
  for (auto it = mask.begin<std::uint16_t>(); it != mask.end<std::uint16_t>(); ++it) {
    if (*it >= 1000) values.insert(*it);
  }
  return values;
}

class MaskSanityTest : public ::testing::Test {
 protected:
  cv::Mat Clean(const cv::Mat& mask, double x_m = 0.0) {
    const Ipm ipm(test::PaintCamera(), test::PaintMount(), 40.0);
    return sanity_.Clean(mask, ipm, test::PlanarPose(x_m, 0.0, 0.0), &counters_);
  }
  const ClassTable classes_ =
      ClassTable::LoadFile(std::string(IRM_SOURCE_DIR) + "/config/classes.yaml");
  MaskSanity sanity_{MaskSanityOptions{}, &classes_};
  MaskSanityCounters counters_;
};

TEST_F(MaskSanityTest, AHatchedAreaIsLeftOutAndCounted) {
  const cv::Mat mask = RenderMask({{test::SolidLine(-1.8, 5, 30), 1001},
                                   {{{12, 4}, 0.8, 3.0, 0.4}, 30001},
                                   {{{14, 4}, 0.8, 3.0, 0.4}, 30001}});
  EXPECT_EQ(Values(Clean(mask)), (std::set<std::uint16_t>{1001}));
  EXPECT_EQ(counters_.area_instances, 1u);
}

TEST_F(MaskSanityTest, TwoLinesInOneInstanceAreSplit) {
  const cv::Mat mask =
      RenderMask({{test::SolidLine(-1.8, 5, 30), 1001}, {test::SolidLine(1.8, 5, 30), 1001}});
  const std::set<std::uint16_t> values = Values(Clean(mask));
  ASSERT_EQ(values.size(), 2u);
  for (const std::uint16_t v : values) EXPECT_EQ(v / 1000, 1);
  EXPECT_EQ(counters_.lane_instances_split, 1u);
}

TEST_F(MaskSanityTest, TheDashesOfOneLineStayOneInstance) {
  std::vector<std::pair<Stripe, std::uint16_t>> dashes;
  for (const Stripe& s : test::DashedLine(1.8, 6.0, 3)) dashes.push_back({s, 2001});
  EXPECT_EQ(Values(Clean(RenderMask(dashes))), (std::set<std::uint16_t>{2001}));
  EXPECT_EQ(counters_.lane_instances_split, 0u);
}

TEST_F(MaskSanityTest, AClassThatFlickersTakesTheClassTheEvidenceHolds) {
  // A solid line seen three frames as solid (class 1), then once as dashed (class 2): the
  // flicker is resolved to solid. The vehicle moves 1 m a frame; the line is fixed in the map.
  for (int frame = 0; frame < 3; ++frame) {
    Clean(RenderMask({{test::SolidLine(-1.8, 5 - frame, 30 - frame), 1001}}), frame);
  }
  const cv::Mat flicker = Clean(RenderMask({{test::SolidLine(-1.8, 2, 27), 2001}}), 3.0);
  const std::set<std::uint16_t> values = Values(flicker);
  ASSERT_EQ(values.size(), 1u);
  EXPECT_EQ(*values.begin() / 1000, 1);
  EXPECT_EQ(counters_.lane_class_resolved, 1u);
  // Without that evidence (another place) the class stays.
  sanity_.Reset();
  EXPECT_EQ(Values(Clean(RenderMask({{test::SolidLine(-1.8, 2, 27), 2001}}), 3.0)),
            (std::set<std::uint16_t>{2001}));
}

}  // namespace
}  // namespace ipm_road_mapper
