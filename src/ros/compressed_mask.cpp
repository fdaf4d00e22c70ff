#include "ipm_road_mapper/ros/compressed_mask.h"

#include <sensor_msgs/image_encodings.h>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstring>
#include <exception>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <vector>

#include "ipm_road_mapper/ros/msg_conversion.h"

namespace ipm_road_mapper {
namespace {

std::string Trim(const std::string& s) {
  const auto first =
      std::find_if_not(s.begin(), s.end(), [](unsigned char c) { return std::isspace(c); });
  const auto last = std::find_if_not(s.rbegin(), s.rend(), [](unsigned char c) {
                      return std::isspace(c);
                    }).base();
  return first < last ? std::string(first, last) : std::string();
}

bool HostIsBigEndian() {
  const std::uint16_t probe = 1;
  std::uint8_t first_byte = 0;
  std::memcpy(&first_byte, &probe, 1);
  return first_byte == 0;
}

std::string Lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

}  // namespace

std::string DecodeCompressedMask(const sensor_msgs::CompressedImage& msg,
                                 sensor_msgs::Image* image) {
  namespace enc = sensor_msgs::image_encodings;
  // "<encoding>; png compressed <...>" (compressed_image_transport) or "png".
  const std::size_t separator = msg.format.find(';');
  std::string encoding =
      separator == std::string::npos ? "" : Trim(msg.format.substr(0, separator));
  const std::string compression =
      Lower(separator == std::string::npos ? msg.format : msg.format.substr(separator + 1));
  if (compression.find("png") == std::string::npos) {
    return "compressed mask format is '" + msg.format +
           "': only png is lossless (set the publisher's format to png)";
  }
  if (encoding.empty()) encoding = enc::TYPE_16UC1;
  if (encoding != enc::TYPE_16UC1 && encoding != enc::MONO16) {
    return "compressed mask encoding is '" + encoding + "', expected 16UC1 or mono16";
  }
  cv::Mat decoded;
  try {
    decoded = cv::imdecode(cv::Mat(1, static_cast<int>(msg.data.size()), CV_8UC1,
                                   const_cast<std::uint8_t*>(msg.data.data())),
                           cv::IMREAD_UNCHANGED);
  } catch (const std::exception& e) {
    return std::string("compressed mask does not decode: ") + e.what();
  }
  if (decoded.empty()) return "compressed mask does not decode as png";
  if (decoded.type() != CV_16UC1) {
    return "compressed mask decodes to " + std::to_string(decoded.channels()) + " channel(s) of " +
           std::to_string(8 * decoded.elemSize1()) + " bits, expected one 16-bit channel";
  }
  image->header = msg.header;
  image->height = static_cast<std::uint32_t>(decoded.rows);
  image->width = static_cast<std::uint32_t>(decoded.cols);
  image->encoding = encoding;
  image->is_bigendian = HostIsBigEndian();
  image->step = static_cast<std::uint32_t>(decoded.cols * 2);
  image->data.resize(static_cast<std::size_t>(image->step) * image->height);
  for (int row = 0; row < decoded.rows; ++row) {
    std::memcpy(image->data.data() + static_cast<std::size_t>(row) * image->step, decoded.ptr(row),
                image->step);
  }
  return "";
}

std::string EncodeCompressedMask(const sensor_msgs::Image& image,
                                 sensor_msgs::CompressedImage* msg) {
  cv::Mat mask;
  const std::string error = ImageToMask(image, &mask);
  if (!error.empty()) return error;
  msg->header = image.header;
  msg->format = image.encoding + "; png compressed ";
  if (!cv::imencode(".png", mask, msg->data)) return "png encoding failed";
  return "";
}

}  // namespace ipm_road_mapper
