#include "ipm_road_mapper/segmentation/openvino/paint_model.h"

#include <openvino/openvino.hpp>
#include <stdexcept>

namespace ipm_road_mapper {
namespace segmentation {

struct PaintModel::Runtime {
  ov::Core core;
  ov::CompiledModel compiled;
  ov::InferRequest request;
};

PaintModel::PaintModel(const std::string& model_path, const PaintModelOptions& options)
    : runtime_(std::make_unique<Runtime>()), options_(options) {
  std::string why;
  model_file_ = FindModelFile(model_path, &why);
  if (model_file_.empty()) throw std::runtime_error(why);
  std::shared_ptr<ov::Model> model = runtime_->core.read_model(model_file_);
  if (model->inputs().size() != 1 || model->outputs().size() != 1) {
    throw std::runtime_error(model_file_ + ": needs one input and one output");
  }
  const ov::PartialShape input = model->input().get_partial_shape();
  if (input.is_dynamic() || input.size() != 4 || input[1].get_length() != 3 ||
      model->input().get_element_type() != ov::element::f32) {
    throw std::runtime_error(model_file_ + ": the input must be a static f32 1x3xHxW image, not " +
                             input.to_string());
  }
  input_size_ =
      cv::Size(static_cast<int>(input[3].get_length()), static_cast<int>(input[2].get_length()));
  runtime_->compiled =
      runtime_->core.compile_model(model, "CPU", ov::inference_num_threads(options.threads),
                                   ov::hint::performance_mode(ov::hint::PerformanceMode::LATENCY));
  runtime_->request = runtime_->compiled.create_infer_request();
  if (runtime_->request.get_output_tensor().get_shape().size() != 4) {
    throw std::runtime_error(model_file_ + ": the output must be 1xCxHxW");
  }
}

PaintModel::~PaintModel() = default;

cv::Mat PaintModel::Infer(const cv::Mat& image_bgr) {
  ov::Tensor input = runtime_->request.get_input_tensor();
  MakeInput(image_bgr, input_size_.width, input_size_.height, options_, input.data<float>());
  runtime_->request.infer();
  const ov::Tensor output = runtime_->request.get_output_tensor();
  const ov::Shape shape = output.get_shape();
  return PaintProbability(output.data<const float>(), static_cast<int>(shape[1]),
                          static_cast<int>(shape[2]), static_cast<int>(shape[3]), options_,
                          image_bgr.size());
}

}  // namespace segmentation
}  // namespace ipm_road_mapper
