// Messages compared byte for byte in the publication tests: a message serialized as ROS sends
// it, and a marker array as the set of its serialized markers (the array up to its order).
#pragma once

#include <ros/serialization.h>
#include <visualization_msgs/MarkerArray.h>

#include <algorithm>
#include <cstdint>
#include <vector>

namespace ipm_road_mapper {
namespace test {

// `message` serialized as it goes on the wire.
template <typename Message>
std::vector<std::uint8_t> Bytes(const Message& message) {
  std::vector<std::uint8_t> bytes(ros::serialization::serializationLength(message));
  ros::serialization::OStream stream(bytes.data(), static_cast<std::uint32_t>(bytes.size()));
  ros::serialization::serialize(stream, message);
  return bytes;
}

// The markers of an array, each serialized, sorted: the array up to its order.
inline std::vector<std::vector<std::uint8_t>> MarkerSet(
    const visualization_msgs::MarkerArray& array) {
  std::vector<std::vector<std::uint8_t>> set;
  for (const visualization_msgs::Marker& m : array.markers) set.push_back(Bytes(m));
  std::sort(set.begin(), set.end());
  return set;
}

}  // namespace test
}  // namespace ipm_road_mapper
