// Compressed masks: a png CompressedImage as image_transport's compressed transport sends
// it decodes into the same 16UC1 mask; lossy or malformed ones are refused with a reason.
#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "ipm_road_mapper/ros/compressed_mask.h"
#include "ipm_road_mapper/ros/msg_conversion.h"

namespace ipm_road_mapper {
namespace {

sensor_msgs::Image SomeMask() {
  cv::Mat mask(48, 64, CV_16UC1, cv::Scalar(0));
  cv::rectangle(mask, cv::Rect(5, 20, 10, 20), cv::Scalar(1001), cv::FILLED);
  cv::rectangle(mask, cv::Rect(30, 10, 20, 8), cv::Scalar(10002), cv::FILLED);
  sensor_msgs::Image image;
  image.header.stamp = ros::Time(12.5);
  image.header.frame_id = "camera";
  image.height = 48;
  image.width = 64;
  image.encoding = "16UC1";
  image.step = 128;
  image.data.assign(mask.datastart, mask.dataend);
  return image;
}

TEST(CompressedMask, PngRoundTripKeepsEveryInstanceId) {
  const sensor_msgs::Image image = SomeMask();
  sensor_msgs::CompressedImage compressed;
  ASSERT_EQ(EncodeCompressedMask(image, &compressed), "");
  EXPECT_EQ(compressed.format, "16UC1; png compressed ");
  EXPECT_LT(compressed.data.size(), image.data.size());
  sensor_msgs::Image decoded;
  ASSERT_EQ(DecodeCompressedMask(compressed, &decoded), "");
  EXPECT_EQ(decoded.header.stamp, image.header.stamp);
  EXPECT_EQ(decoded.header.frame_id, "camera");
  cv::Mat a, b;
  ASSERT_EQ(ImageToMask(image, &a), "");
  ASSERT_EQ(ImageToMask(decoded, &b), "");
  EXPECT_EQ(cv::countNonZero(a != b), 0);
  // A bare "png" format (no encoding named) is read as 16UC1.
  compressed.format = "png";
  ASSERT_EQ(DecodeCompressedMask(compressed, &decoded), "");
  EXPECT_EQ(decoded.encoding, "16UC1");
}

TEST(CompressedMask, LossyOrMalformedMasksAreRefused) {
  sensor_msgs::CompressedImage compressed;
  ASSERT_EQ(EncodeCompressedMask(SomeMask(), &compressed), "");
  sensor_msgs::Image decoded;
  compressed.format = "16UC1; jpeg compressed ";
  EXPECT_NE(DecodeCompressedMask(compressed, &decoded).find("only png"), std::string::npos);
  compressed.format = "bgr8; png compressed ";
  EXPECT_NE(DecodeCompressedMask(compressed, &decoded).find("expected 16UC1"), std::string::npos);
  compressed.format = "16UC1; png compressed ";
  compressed.data.resize(20);  // truncated
  EXPECT_NE(DecodeCompressedMask(compressed, &decoded), "");
  // An 8-bit png is not a mask.
  cv::Mat eight(4, 4, CV_8UC1, cv::Scalar(3));
  cv::imencode(".png", eight, compressed.data);
  EXPECT_NE(DecodeCompressedMask(compressed, &decoded).find("16-bit"), std::string::npos);
}

}  // namespace
}  // namespace ipm_road_mapper
