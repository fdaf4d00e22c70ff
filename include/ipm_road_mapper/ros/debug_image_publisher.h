// ~debug_image: the map projected over the camera image next to the frame's measurements
// (core/debug_overlay.h). Lazy: the image topic is subscribed, and overlays are drawn,
// only while ~debug_image has subscribers. A used frame is drawn over the camera image of
// the same stamp (kept in a short ring; a frame whose image arrives later waits in a
// one-frame slot); without any image for 2 s, over the mask itself. The image callback
// only hands the image to `enqueue` (the nodelet's input queue); the mapping thread then
// calls AddImage and AddFrame, so all drawing happens there, never in a data callback.
#pragma once

#include <ros/node_handle.h>
#include <ros/publisher.h>
#include <ros/subscriber.h>
#include <sensor_msgs/Image.h>

#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "ipm_road_mapper/core/frontend/class_table.h"
#include "ipm_road_mapper/core/map/vector_map.h"
#include "ipm_road_mapper/core/mapper/mapper.h"
#include "ipm_road_mapper/core/mapper/mapper_options.h"

namespace ipm_road_mapper {

class DebugImagePublisher {
 public:
  // Advertises ~debug_image on `private_nh`; subscribes `image_topic` on `nh` on demand and
  // hands each image to `enqueue`.
  DebugImagePublisher(ros::NodeHandle& nh, ros::NodeHandle& private_nh, std::string image_topic,
                      MapperOptions options, ClassTable classes,
                      std::function<void(const sensor_msgs::ImageConstPtr&)> enqueue);
  ~DebugImagePublisher();

  // True while someone subscribes to ~debug_image.
  bool active() const;

  // A frame the mapper used, with its corrected pose, the extrinsic and the map after it.
  void AddFrame(const FrameInput& frame, const Eigen::Isometry3d& T_map_base,
                const Eigen::Isometry3d& T_base_cam, std::shared_ptr<const VectorMap> map);

  // A camera image (from the mapping thread): kept in the ring; draws the waiting frame of
  // its stamp.
  void AddImage(const sensor_msgs::ImageConstPtr& image);

  // Unsubscribes and stops drawing (before the nodelet goes away).
  void Shutdown();

 private:
  struct PendingFrame {
    FrameInput frame;
    Eigen::Isometry3d T_map_base;
    Eigen::Isometry3d T_base_cam;
    std::shared_ptr<const VectorMap> map;
  };
  void OnConnection();
  void Draw(const PendingFrame& frame, const sensor_msgs::ImageConstPtr& image);

  ros::NodeHandle nh_;
  std::string image_topic_;
  MapperOptions options_;
  ClassTable classes_;
  std::function<void(const sensor_msgs::ImageConstPtr&)> enqueue_;
  mutable std::mutex mutex_;  // everything below
  ros::Publisher pub_;
  ros::Subscriber image_sub_;
  bool shut_down_ = false;
  std::deque<sensor_msgs::ImageConstPtr> images_;  // newest last
  std::optional<PendingFrame> pending_;
  ros::WallTime last_image_wall_;
};

}  // namespace ipm_road_mapper
