#include "ipm_road_mapper/segmentation/openvino/frame_segmenter.h"

#include <chrono>
#include <filesystem>

namespace ipm_road_mapper {
namespace segmentation {

SegmentationConfig LoadSegmentationConfig(const std::string& path,
                                          const std::string& model_folder) {
  OptionsReader root = OptionsReader::FromFile(path);
  SegmentationConfig config;
  config.model = LoadPaintModelOptions(root.Child("model"));
  config.instances = LoadInstanceOptions(root.Child("instances"));
  root.RejectUnknownKeys();
  std::error_code error;
  const std::filesystem::path own = std::filesystem::path(model_folder) / "paint_model.yaml";
  if (!model_folder.empty() && std::filesystem::is_regular_file(own, error)) {
    OptionsReader user = OptionsReader::FromFile(own.string());
    config.model = LoadPaintModelOptions(user.Child("model"));
    user.RejectUnknownKeys();
  }
  return config;
}

FrameSegmenter::FrameSegmenter(const std::string& model_path, const SegmentationConfig& config)
    : model_(model_path, config.model), instancer_(config.instances) {}

FrameSegmenter::Result FrameSegmenter::Segment(const cv::Mat& image, const PinholeCamera& camera,
                                               const Eigen::Isometry3d& T_base_cam) {
  using Clock = std::chrono::steady_clock;
  const auto ms = [](Clock::time_point a, Clock::time_point b) {
    return std::chrono::duration<double, std::milli>(b - a).count();
  };
  Result result;
  const Clock::time_point start = Clock::now();
  result.paint_probability = model_.Infer(image);
  const Clock::time_point inferred = Clock::now();
  result.frame = instancer_.Run(result.paint_probability, camera, T_base_cam);
  result.inference_ms = ms(start, inferred);
  result.instances_ms = ms(inferred, Clock::now());
  return result;
}

}  // namespace segmentation
}  // namespace ipm_road_mapper
