// The segmentation front end (network + ground-plane instancer) on real KITTI frames
// (../shared/data/kitti_onramp, ../shared/models/road-segmentation-adas-0001): bounds on the
// instances and their classes. Skips when the clip or the model is absent.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <map>
#include <opencv2/imgcodecs.hpp>

#include "common/test_scene.h"
#include "ipm_road_mapper/segmentation/openvino/frame_segmenter.h"

namespace ipm_road_mapper {
namespace {

namespace fs = std::filesystem;
using segmentation::PaintClass;

const std::string kClip = std::string(IRM_SHARED_DIR) + "/data/kitti_onramp";
const std::string kModel = std::string(IRM_SHARED_DIR) + "/models/road-segmentation-adas-0001";

class KittiFrames : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (!fs::is_directory(kClip) || !fs::is_directory(kModel)) return;
    const std::string config = std::string(IRM_SOURCE_DIR) + "/config/segmentation.yaml";
    segmenter_ = new segmentation::FrameSegmenter(
        kModel, segmentation::LoadSegmentationConfig(config, kModel));
  }
  static void TearDownTestSuite() {
    delete segmenter_;
    segmenter_ = nullptr;
  }
  void SetUp() override {
    if (!segmenter_) GTEST_SKIP() << "skipped: " << kClip << " or " << kModel << " absent";
  }

  // Instances by class of frame `index`: the clip's camera (calib.txt P0) level at 1.65 m
  // above the road, as kitti_to_bag.py gives it to the mapper.
  static std::map<PaintClass, int> Segment(int index) {
    char name[32];
    std::snprintf(name, sizeof(name), "/image_l/%06d.png", index);
    const cv::Mat image = cv::imread(kClip + name, cv::IMREAD_GRAYSCALE);
    EXPECT_FALSE(image.empty()) << name;
    const CameraIntrinsics camera = test::Intrinsics(1241, 376, 718.856, 607.1928, 185.2157);
    const auto result = segmenter_->Segment(image, PinholeCamera(camera),
                                            test::MountedCamera(0, 0, 0, {0, 0, 1.65}));
    std::map<PaintClass, int> count;
    for (const auto& instance : result.frame.instances) {
      ++count[instance.paint_class];
      EXPECT_GT(instance.confidence, 0.0);
      EXPECT_LE(instance.confidence, 1.0);
      EXPECT_GT(instance.pixels, 0);
    }
    return count;
  }

  static segmentation::FrameSegmenter* segmenter_;
};

segmentation::FrameSegmenter* KittiFrames::segmenter_ = nullptr;

TEST_F(KittiFrames, TheChevronAreaIsHatchedNotLanes) {
  std::map<PaintClass, int> count = Segment(10);
  EXPECT_GE(count[PaintClass::kHatchedArea], 1);
  EXPECT_LE(count[PaintClass::kHatchedArea], 4);
  EXPECT_LE(count[PaintClass::kLaneSolid] + count[PaintClass::kLaneDashed], 4);
  EXPECT_EQ(count[PaintClass::kStopLine], 0);
}

TEST_F(KittiFrames, TheStraightRoadHasItsEdgeAndCenterLines) {
  for (const int index : {40, 48}) {
    std::map<PaintClass, int> count = Segment(index);
    EXPECT_GE(count[PaintClass::kLaneSolid], 2) << index;
    EXPECT_GE(count[PaintClass::kLaneDashed], 1) << index;
    EXPECT_LE(count[PaintClass::kLaneSolid] + count[PaintClass::kLaneDashed], 6) << index;
    EXPECT_EQ(count[PaintClass::kHatchedArea], 0) << index;
    EXPECT_EQ(count[PaintClass::kCrossingStripe], 0) << index;
    EXPECT_EQ(count[PaintClass::kStopLine], 0) << index;
  }
}

}  // namespace
}  // namespace ipm_road_mapper
