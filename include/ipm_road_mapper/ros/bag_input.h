// Reading the mapper's input from a bag file with the rosbag C++ API (no roscore): opening
// (with what a bag without its index needs), topic checks, the first mask's frame and the
// camera extrinsic from /tf_static (camera_info <-> mask pairing: bag_camera_info.h). Used by the
// offline runner (map_from_bag); errors are one line, never exceptions.
#pragma once

#include <rosbag/bag.h>

#include <Eigen/Geometry>
#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace ipm_road_mapper {

// What the file header of a bag says about its index (rosbag::Bag refuses to open a bag
// without one: a bag cut short, or one whose recording was never closed).
struct BagIndexCheck {
  bool is_bag_v2 = false;      // starts with "#ROSBAG V2.0" and a readable file header
  bool index_missing = false;  // index position 0 (not closed) or past the end (truncated)
  std::string problem;         // one phrase, e.g. "it is truncated: ..."; empty when fine
};

// Reads only the bag's version line and file header record (a few hundred bytes).
BagIndexCheck CheckBagIndex(const std::string& path);

// Opens the bag at `path` for reading into *bag. Empty on success, otherwise one line
// "<path>: cannot read bag: ..." that, for a bag without its index (CheckBagIndex) or with a
// damaged one, says so and suggests `rosbag reindex <path>`. console_bridge (cpp_common's
// header parser logs a damaged record to it) is silenced while the bag is opened.
std::string OpenBagForReading(const std::string& path, rosbag::Bag* bag);

// The header.frame_id of the first mask on `mask_topic` that can be read ("" when none can,
// or it is not a sensor_msgs/Image). After a read error (a corrupt chunk) the bag is reopened,
// as rosbag's chunk cache may then be wrong (bag_prefetcher.cpp).
std::string FirstReadableMaskFrame(rosbag::Bag* bag, const std::string& mask_topic);

// Topic -> message type (e.g. "sensor_msgs/Image") of every connection in the bag.
std::map<std::string, std::string> BagTopicTypes(const rosbag::Bag& bag);

// Checks that each (topic, type) of `required` is in the bag with that type. Empty when all
// are, otherwise one line naming the first missing topic and listing the bag's topics.
std::string CheckBagTopics(const rosbag::Bag& bag,
                           const std::vector<std::pair<std::string, std::string>>& required);

// The static transform T_parent_child (maps child-frame points into the parent frame) from
// the bag's /tf_static, composing a chain of transforms when needed (tf2::BufferCore).
// Empty on success, otherwise why it is not available (also when a /tf_static message is in
// an unreadable chunk).
std::string LookupStaticTransform(const rosbag::Bag& bag, const std::string& parent_frame,
                                  const std::string& child_frame, Eigen::Isometry3d* T);

}  // namespace ipm_road_mapper
