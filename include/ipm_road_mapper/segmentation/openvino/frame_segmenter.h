// One camera frame in, the instance mask out: the network (PaintModel) and the ground-plane
// instancer (PaintInstancer) with the time each took. What segment_bag and the
// segment_masks nodelet share.
#pragma once

#include <string>

#include "ipm_road_mapper/segmentation/openvino/paint_model.h"
#include "ipm_road_mapper/segmentation/paint_instancer.h"

namespace ipm_road_mapper {
namespace segmentation {

// config/segmentation.yaml: the network's class table and the instancer's rules.
struct SegmentationConfig {
  PaintModelOptions model;
  InstanceOptions instances;
};

// Loads the file; a `paint_model.yaml` beside a user's model overrides the `model` section
// (model_folder may be empty). Throws OptionsError naming a bad key.
SegmentationConfig LoadSegmentationConfig(const std::string& path, const std::string& model_folder);

class FrameSegmenter {
 public:
  // Throws std::runtime_error when the model cannot be loaded.
  FrameSegmenter(const std::string& model_path, const SegmentationConfig& config);

  struct Result {
    SegmentedFrame frame;
    cv::Mat paint_probability;  // CV_32F, the image's size: the network's paint
    double inference_ms = 0.0;  // the network
    double instances_ms = 0.0;  // the ground-plane split and classes
  };

  // `image`: CV_8UC1 or CV_8UC3 (BGR), the camera's size.
  Result Segment(const cv::Mat& image, const PinholeCamera& camera,
                 const Eigen::Isometry3d& T_base_cam);

  const PaintModel& model() const { return model_; }
  PaintInstancer& instancer() { return instancer_; }

 private:
  PaintModel model_;
  PaintInstancer instancer_;
};

}  // namespace segmentation
}  // namespace ipm_road_mapper
