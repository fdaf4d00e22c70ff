// What the package needs to know of a segmentation network (its "class table"): which
// output channels are road paint, how its input is made from an image and what its output
// holds. The default is Open Model Zoo's road-segmentation-adas-0001 (docs/segmentation.md);
// a user's own model (OpenVINO IR or ONNX) plugs in with its own values. No OpenVINO here:
// the decoding is plain arithmetic, tested without a runtime.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "ipm_road_mapper/core/io/yaml_options.h"

namespace ipm_road_mapper {
namespace segmentation {

enum class ModelOutput { kProbabilities, kLogits };

// config/segmentation.yaml, section `model` (and a model folder's own `paint_model.yaml`).
struct PaintModelOptions {
  std::vector<int> paint_channels{3};  // output channels whose sum is the paint probability
  std::string input_color = "bgr";     // bgr | rgb: the channel order the network expects
  std::vector<double> input_mean{0.0, 0.0, 0.0};     // input = (pixel - mean) * scale
  std::vector<double> input_scale{1.0, 1.0, 1.0};    // per channel, in input_color order
  ModelOutput output = ModelOutput::kProbabilities;  // logits: a softmax over channels first
  int threads = 1;                                   // inference threads (OpenVINO's CPU plugin)
};

// Reads the section; throws OptionsError naming a bad or unknown key.
PaintModelOptions LoadPaintModelOptions(OptionsReader reader);

// The model file in `path`: the path itself when it is a .xml or .onnx file, else the one
// .xml (OpenVINO IR) or .onnx in the folder or its FP32/ subfolder. Empty when none is
// found or the choice is ambiguous; *why says which.
std::string FindModelFile(const std::string& path, std::string* why);

// A camera image (CV_8UC1 gray, CV_8UC3 in `image_bgr` order) as the network's input:
// resized to width x height (bilinear), channels in input_color order, normalized, planar
// (NCHW), written to `input` (3 * height * width floats).
void MakeInput(const cv::Mat& image_bgr, int width, int height, const PaintModelOptions& options,
               float* input);

// The paint probability at the image's size (CV_32F in [0, 1]) from the network's NCHW
// output `output` (channels x height x width floats), resized bilinearly. Throws
// std::invalid_argument when a paint channel is not in the output.
cv::Mat PaintProbability(const float* output, int channels, int height, int width,
                         const PaintModelOptions& options, const cv::Size& image_size);

}  // namespace segmentation
}  // namespace ipm_road_mapper
