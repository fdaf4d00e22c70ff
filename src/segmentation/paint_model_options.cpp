#include "ipm_road_mapper/segmentation/paint_model_options.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace ipm_road_mapper {
namespace segmentation {
namespace {

namespace fs = std::filesystem;

std::string CheckThree(const std::vector<double>& v) {
  return v.size() == 3 ? "" : "must hold 3 numbers (got " + std::to_string(v.size()) + ")";
}

// The .xml and .onnx files directly in `folder`.
std::vector<fs::path> ModelFilesIn(const fs::path& folder) {
  std::vector<fs::path> found;
  std::error_code error;
  if (!fs::is_directory(folder, error)) return found;
  for (const fs::directory_entry& entry : fs::directory_iterator(folder, error)) {
    const std::string ext = entry.path().extension().string();
    if (entry.is_regular_file() && (ext == ".xml" || ext == ".onnx")) found.push_back(entry);
  }
  std::sort(found.begin(), found.end());
  return found;
}

}  // namespace

PaintModelOptions LoadPaintModelOptions(OptionsReader reader) {
  PaintModelOptions o;
  reader.Read<std::vector<int>>("paint_channels", &o.paint_channels,
                                [](const std::vector<int>& v) -> std::string {
                                  if (v.empty()) return "must name at least one channel";
                                  for (const int c : v) {
                                    if (c < 0)
                                      return "channels are >= 0 (got " + std::to_string(c) + ")";
                                  }
                                  return "";
                                });
  reader.Read<std::string>("input_color", &o.input_color, [](const std::string& v) {
    return v == "bgr" || v == "rgb" ? std::string() : "must be bgr or rgb (got '" + v + "')";
  });
  reader.Read<std::vector<double>>("input_mean", &o.input_mean, CheckThree);
  reader.Read<std::vector<double>>("input_scale", &o.input_scale, CheckThree);
  std::string output = "probabilities";
  reader.Read<std::string>("output", &output, [](const std::string& v) {
    return v == "probabilities" || v == "logits"
               ? std::string()
               : "must be probabilities or logits (got '" + v + "')";
  });
  o.output = output == "logits" ? ModelOutput::kLogits : ModelOutput::kProbabilities;
  reader.Read<int>("threads", &o.threads, CheckPositiveInt);
  reader.RejectUnknownKeys();
  return o;
}

std::string FindModelFile(const std::string& path, std::string* why) {
  const fs::path p(path);
  std::error_code error;
  const std::string ext = p.extension().string();
  if (fs::is_regular_file(p, error) && (ext == ".xml" || ext == ".onnx")) return path;
  if (!fs::is_directory(p, error)) {
    *why = "'" + path + "' is neither a .xml/.onnx file nor a folder";
    return "";
  }
  for (const fs::path& folder : {p, p / "FP32"}) {
    const std::vector<fs::path> files = ModelFilesIn(folder);
    if (files.size() == 1) return files.front().string();
    if (files.size() > 1) {
      *why = "'" + folder.string() + "' holds several models; name the file";
      return "";
    }
  }
  *why = "no .xml (OpenVINO IR) or .onnx model in '" + path + "' or its FP32/";
  return "";
}

void MakeInput(const cv::Mat& image_bgr, int width, int height, const PaintModelOptions& options,
               float* input) {
  cv::Mat bgr;
  if (image_bgr.channels() == 1) {
    cv::cvtColor(image_bgr, bgr, cv::COLOR_GRAY2BGR);
  } else {
    bgr = image_bgr;
  }
  cv::Mat resized;
  cv::resize(bgr, resized, cv::Size(width, height), 0.0, 0.0, cv::INTER_LINEAR);
  const bool rgb = options.input_color == "rgb";
  const std::size_t plane = static_cast<std::size_t>(width) * height;
  for (int y = 0; y < height; ++y) {
    const cv::Vec3b* row = resized.ptr<cv::Vec3b>(y);
    for (int x = 0; x < width; ++x) {
      for (int c = 0; c < 3; ++c) {
        const int source = rgb ? 2 - c : c;  // resized is BGR
        input[c * plane + static_cast<std::size_t>(y) * width + x] =
            static_cast<float>((row[x][source] - options.input_mean[c]) * options.input_scale[c]);
      }
    }
  }
}

cv::Mat PaintProbability(const float* output, int channels, int height, int width,
                         const PaintModelOptions& options, const cv::Size& image_size) {
  for (const int c : options.paint_channels) {
    if (c >= channels) {
      throw std::invalid_argument("paint channel " + std::to_string(c) + " is not in the " +
                                  std::to_string(channels) + "-channel output");
    }
  }
  const std::size_t plane = static_cast<std::size_t>(width) * height;
  cv::Mat paint(height, width, CV_32F);
  float* p = paint.ptr<float>();
  for (std::size_t i = 0; i < plane; ++i) {
    double sum = 0.0, paint_sum = 0.0, peak = -1e30;
    if (options.output == ModelOutput::kLogits) {
      for (int c = 0; c < channels; ++c) peak = std::max<double>(peak, output[c * plane + i]);
      for (int c = 0; c < channels; ++c) sum += std::exp(output[c * plane + i] - peak);
      for (const int c : options.paint_channels)
        paint_sum += std::exp(output[c * plane + i] - peak);
      p[i] = static_cast<float>(paint_sum / sum);
    } else {
      for (const int c : options.paint_channels) paint_sum += output[c * plane + i];
      p[i] = static_cast<float>(std::clamp(paint_sum, 0.0, 1.0));
    }
  }
  cv::Mat resized;
  cv::resize(paint, resized, image_size, 0.0, 0.0, cv::INTER_LINEAR);
  return resized;
}

}  // namespace segmentation
}  // namespace ipm_road_mapper
