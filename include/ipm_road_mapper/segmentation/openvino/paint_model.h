// The segmentation network on OpenVINO's runtime (from its PyPI wheel, which carries the C++
// headers and libraries: scripts/setup_openvino.sh): an image in, the paint probability
// out. Built only when OpenVINO is found (CMakeLists.txt).
#pragma once

#include <memory>
#include <opencv2/core.hpp>
#include <string>

#include "ipm_road_mapper/segmentation/paint_model_options.h"

namespace ipm_road_mapper {
namespace segmentation {

class PaintModel {
 public:
  // Loads and compiles the model (an OpenVINO IR .xml or an .onnx file, FindModelFile) for
  // the CPU with options.threads threads. Throws std::runtime_error with the reason (no
  // file, not one float image input of 3 channels, a dynamic input shape, no 4-D output).
  PaintModel(const std::string& model_path, const PaintModelOptions& options);
  ~PaintModel();
  PaintModel(const PaintModel&) = delete;
  PaintModel& operator=(const PaintModel&) = delete;

  // Paint probability (CV_32F in [0, 1], the image's size) of a CV_8UC1 or CV_8UC3 (BGR)
  // image.
  cv::Mat Infer(const cv::Mat& image_bgr);

  const std::string& model_file() const { return model_file_; }
  cv::Size input_size() const { return input_size_; }

 private:
  struct Runtime;
  std::unique_ptr<Runtime> runtime_;
  PaintModelOptions options_;
  std::string model_file_;
  cv::Size input_size_;
};

}  // namespace segmentation
}  // namespace ipm_road_mapper
