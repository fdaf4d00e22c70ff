// Reading the mapper's input from a bag file with the rosbag C++ API (no roscore): topic
// checks, the camera extrinsic from /tf_static, and camera_info <-> mask pairing. Used by
// the offline runner (map_from_bag); errors are one line, never exceptions.
#pragma once

#include <ros/time.h>
#include <rosbag/bag.h>

#include <Eigen/Geometry>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "ipm_road_mapper/core/geometry/pinhole_camera.h"

namespace ipm_road_mapper {

// Topic -> message type (e.g. "sensor_msgs/Image") of every connection in the bag.
std::map<std::string, std::string> BagTopicTypes(const rosbag::Bag& bag);

// Checks that each (topic, type) of `required` is in the bag with that type. Empty when all
// are, otherwise one line naming the first missing topic and listing the bag's topics.
std::string CheckBagTopics(const rosbag::Bag& bag,
                           const std::vector<std::pair<std::string, std::string>>& required);

// The static transform T_parent_child (maps child-frame points into the parent frame) from
// the bag's /tf_static, composing a chain of transforms when needed (tf2::BufferCore).
// Empty on success, otherwise why it is not available.
std::string LookupStaticTransform(const rosbag::Bag& bag, const std::string& parent_frame,
                                  const std::string& child_frame, Eigen::Isometry3d* T);

// Every camera_info of a topic, indexed by stamp, to pair masks with (docs/design.md §2: masks and
// camera_info share a stamp). Sync "exact" needs the identical stamp; "approximate" takes the
// nearest camera_info within half a frame period (the median camera_info period).
class CameraInfoTable {
 public:
  // Reads the whole topic (camera_info messages are small). Messages that do not convert
  // are kept with their error, so a mask paired with one reports it.
  static CameraInfoTable Read(const rosbag::Bag& bag, const std::string& topic);

  // The intrinsics for a mask stamped `stamp` (compared as ros::Time, not as a double, so
  // "exact" is exact). Empty on success, otherwise a skip reason "no_camera_info: ..." or
  // "bad_camera_info: ...".
  std::string Match(const ros::Time& stamp, bool exact, CameraIntrinsics* intrinsics) const;

  std::size_t size() const { return entries_.size(); }
  // Half the median period between consecutive camera_info stamps (0.05 s with < 2 of them).
  double approximate_tolerance_s() const { return approximate_tolerance_s_; }

 private:
  struct Entry {
    ros::Time stamp;
    CameraIntrinsics intrinsics;
    std::string error;  // conversion error, empty when usable
  };
  std::vector<Entry> entries_;  // sorted by stamp
  double approximate_tolerance_s_ = 0.05;
};

}  // namespace ipm_road_mapper
