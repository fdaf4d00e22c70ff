#include "ipm_road_mapper/ros/segmentation/segmentation_overlay.h"

#include <map>
#include <opencv2/imgproc.hpp>

namespace ipm_road_mapper {

cv::Mat SegmentationOverlay(const cv::Mat& image, const cv::Mat& paint,
                            const segmentation::SegmentedFrame& frame) {
  using segmentation::PaintClass;
  static const std::map<PaintClass, cv::Vec3b> kColours = {
      {PaintClass::kLaneSolid, {0, 220, 0}},        {PaintClass::kLaneDashed, {255, 255, 0}},
      {PaintClass::kCrossingStripe, {0, 255, 255}}, {PaintClass::kStopLine, {0, 0, 255}},
      {PaintClass::kArrow, {255, 0, 255}},          {PaintClass::kHatchedArea, {0, 140, 255}}};
  cv::Mat out;
  if (image.channels() == 1) {
    cv::cvtColor(image, out, cv::COLOR_GRAY2BGR);
  } else {
    out = image.clone();
  }
  std::map<std::uint16_t, cv::Vec3b> colour_of;
  for (const segmentation::SegmentedInstance& instance : frame.instances) {
    // Instances of one class told apart by brightness.
    const double shade = 0.6 + 0.4 * ((instance.value % 1000) % 3) / 2.0;
    colour_of[instance.value] = kColours.at(instance.paint_class) * shade;
  }
  for (int v = 0; v < out.rows; ++v) {
    for (int u = 0; u < out.cols; ++u) {
      const std::uint16_t value = frame.mask.at<std::uint16_t>(v, u);
      if (value >= 1000) {
        out.at<cv::Vec3b>(v, u) = colour_of[value];
      } else if (!paint.empty() && paint.at<uchar>(v, u)) {
        out.at<cv::Vec3b>(v, u) = {128, 128, 128};
      }
    }
  }
  if (frame.ground_view.empty()) return out;
  // The ground view beside the image, scaled to its height.
  cv::Mat ground(frame.ground_view.size(), CV_8UC3, cv::Scalar(40, 40, 40));
  for (int r = 0; r < ground.rows; ++r) {
    for (int c = 0; c < ground.cols; ++c) {
      const std::uint16_t value = frame.ground_view.at<std::uint16_t>(r, c);
      if (value >= 1000) {
        ground.at<cv::Vec3b>(r, c) = colour_of[value];
      } else if (value > 0) {
        ground.at<cv::Vec3b>(r, c) = {128, 128, 128};
      }
    }
  }
  const double scale = static_cast<double>(out.rows) / ground.rows;
  cv::resize(ground, ground, cv::Size(), scale, scale, cv::INTER_AREA);
  cv::Mat both;
  cv::hconcat(out, ground, both);
  return both;
}

}  // namespace ipm_road_mapper
