// Masks that arrive compressed (sensor_msgs/CompressedImage on <mask_topic>/compressed, as
// image_transport's "compressed" transport publishes them): decoded back into the
// sensor_msgs/Image the mapper reads. Only lossless PNG is accepted: JPEG would blend the
// instance ids of neighbouring pixels into ids that do not exist.
#pragma once

#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>

#include <string>

namespace ipm_road_mapper {

// Decodes `msg` (format "<encoding>; png compressed ..." as compressed_image_transport
// writes it, or a bare "png") into `image` (header copied; encoding from the format, 16UC1
// when it names none). Returns "" or why it cannot (not PNG, undecodable, not 16-bit
// single-channel).
std::string DecodeCompressedMask(const sensor_msgs::CompressedImage& msg,
                                 sensor_msgs::Image* image);

// A CompressedImage of `image` (16UC1 or mono16) in that format, PNG-encoded: what
// compressed_image_transport would publish (for tests and tools). Returns "" or the error.
std::string EncodeCompressedMask(const sensor_msgs::Image& image,
                                 sensor_msgs::CompressedImage* msg);

}  // namespace ipm_road_mapper
