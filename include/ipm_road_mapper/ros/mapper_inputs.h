// What the nodelet's data callbacks hand to the mapping thread: the message already
// converted to the core's types (cheap), so the callback never waits on the mapper.
#pragma once

#include <sensor_msgs/Image.h>

#include <opencv2/core.hpp>
#include <string>
#include <variant>

#include "ipm_road_mapper/core/geometry/pinhole_camera.h"
#include "ipm_road_mapper/core/geometry/rigid_transform.h"

namespace ipm_road_mapper {

// A synchronized mask + camera_info pair; `error` set when either could not be converted
// ("<reason key>: <detail>", counted as a skipped frame).
struct FrameItem {
  double stamp = 0.0;
  cv::Mat mask;  // CV_16UC1
  CameraIntrinsics camera;
  std::string camera_frame;  // the mask's header.frame_id (extrinsic lookup)
  std::string error;
};

// One odometry message (a NaN pose when it could not be converted: bad_odometry).
struct OdometryItem {
  StampedPose pose;
  std::string frame_id;  // header.frame_id: the map frame unless ros/map_frame is set
};

// A camera image for ~debug_image (drawn in the mapping thread).
struct ImageItem {
  sensor_msgs::ImageConstPtr image;
};

using MapperInputItem = std::variant<FrameItem, OdometryItem, ImageItem>;

// Kinds of input items, for drop counters and logs.
enum class InputKind { kFrame = 0, kOdometry = 1, kImage = 2 };
constexpr std::size_t kInputKindCount = 3;

// The kind of an item and its name ("frame", "odometry", "image").
inline InputKind KindOf(const MapperInputItem& item) {
  return static_cast<InputKind>(item.index());
}
inline const char* InputKindName(InputKind kind) {
  static const char* kNames[kInputKindCount] = {"frame", "odometry", "image"};
  return kNames[static_cast<std::size_t>(kind)];
}

}  // namespace ipm_road_mapper
