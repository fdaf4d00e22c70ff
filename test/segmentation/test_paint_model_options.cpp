// The network's class table without a runtime: finding the model file, making the input,
// decoding the output into the paint probability.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "ipm_road_mapper/segmentation/paint_model_options.h"

namespace ipm_road_mapper {
namespace {

namespace fs = std::filesystem;
using segmentation::PaintModelOptions;

OptionsReader Reader(const std::string& yaml) { return OptionsReader(YAML::Load(yaml), "model"); }

TEST(PaintModelOptions, FindsTheOneModelOfAFolderOrItsFp32) {
  const fs::path root = fs::temp_directory_path() / "irm_find_model";
  fs::remove_all(root);
  fs::create_directories(root / "FP32");
  std::string why;
  EXPECT_EQ(segmentation::FindModelFile(root.string(), &why), "");
  EXPECT_NE(why.find("no .xml"), std::string::npos);
  std::ofstream(root / "FP32" / "net.xml") << "<net/>";
  EXPECT_EQ(segmentation::FindModelFile(root.string(), &why), (root / "FP32" / "net.xml").string());
  std::ofstream(root / "a.onnx") << "x";
  EXPECT_EQ(segmentation::FindModelFile(root.string(), &why), (root / "a.onnx").string());
  std::ofstream(root / "b.onnx") << "x";
  EXPECT_EQ(segmentation::FindModelFile(root.string(), &why), "");
  EXPECT_NE(why.find("several"), std::string::npos);
  fs::remove_all(root);
}

TEST(PaintModelOptions, ProbabilitiesSumThePaintChannels) {
  // 3 channels of 1 x 2: channel 1 and 2 are paint.
  const std::vector<float> out = {0.5f, 0.1f, 0.2f, 0.3f, 0.3f, 0.6f};
  PaintModelOptions options;
  options.paint_channels = {1, 2};
  const cv::Mat paint = segmentation::PaintProbability(out.data(), 3, 1, 2, options, {2, 1});
  EXPECT_NEAR(paint.at<float>(0, 0), 0.5f, 1e-6);
  EXPECT_NEAR(paint.at<float>(0, 1), 0.9f, 1e-6);
  options.paint_channels = {3};
  EXPECT_THROW(segmentation::PaintProbability(out.data(), 3, 1, 2, options, {2, 1}),
               std::invalid_argument);
}

TEST(PaintModelOptions, LogitsGoThroughASoftmax) {
  const std::vector<float> out = {0.0f, std::log(3.0f)};  // 2 channels of 1 x 1
  PaintModelOptions options;
  options.paint_channels = {1};
  options.output = segmentation::ModelOutput::kLogits;
  const cv::Mat paint = segmentation::PaintProbability(out.data(), 2, 1, 1, options, {1, 1});
  EXPECT_NEAR(paint.at<float>(0, 0), 0.75f, 1e-5);
}

TEST(PaintModelOptions, InputIsPlanarInTheNetworksOrder) {
  cv::Mat bgr(1, 1, CV_8UC3, cv::Scalar(10, 20, 30));
  PaintModelOptions options;
  options.input_color = "rgb";
  options.input_mean = {1.0, 2.0, 3.0};
  options.input_scale = {0.5, 0.5, 0.5};
  std::vector<float> input(3);
  segmentation::MakeInput(bgr, 1, 1, options, input.data());
  EXPECT_FLOAT_EQ(input[0], (30 - 1) * 0.5f);  // R first
  EXPECT_FLOAT_EQ(input[2], (10 - 3) * 0.5f);
  cv::Mat gray(1, 1, CV_8UC1, cv::Scalar(40));
  options.input_color = "bgr";
  segmentation::MakeInput(gray, 1, 1, options, input.data());
  EXPECT_FLOAT_EQ(input[1], (40 - 2) * 0.5f);
}

TEST(PaintModelOptions, UnknownKeysAndBadValuesAreRefused) {
  EXPECT_THROW(segmentation::LoadPaintModelOptions(Reader("paint_chanels: [3]")), OptionsError);
  EXPECT_THROW(segmentation::LoadPaintModelOptions(Reader("input_color: hsv")), OptionsError);
  EXPECT_THROW(segmentation::LoadPaintModelOptions(Reader("input_mean: [1, 2]")), OptionsError);
  EXPECT_EQ(
      segmentation::LoadPaintModelOptions(Reader("paint_channels: [2, 3]")).paint_channels.size(),
      2u);
}

}  // namespace
}  // namespace ipm_road_mapper
