#include "ipm_road_mapper/ros/map_publisher.h"

#include <nav_msgs/Path.h>
#include <visualization_msgs/MarkerArray.h>

#include "ipm_road_mapper/ros/msg_conversion.h"
#include "ipm_road_mapper/ros/vector_map_conversion.h"

namespace ipm_road_mapper {

MapPublisher::MapPublisher(ros::NodeHandle& private_nh, int path_max_poses)
    : path_max_poses_(path_max_poses) {
  vector_map_pub_ = private_nh.advertise<ipm_road_mapper::VectorMapMsg>("vector_map", 1, true);
  markers_pub_ = private_nh.advertise<visualization_msgs::MarkerArray>("markers", 1, true);
  path_pub_ = private_nh.advertise<nav_msgs::Path>("corrected_path", 1, true);
}

void MapPublisher::Publish(const VectorMap& map, const std::string& map_frame,
                           const std::string& base_frame, const std::string& refined_camera_frame,
                           const ros::Time& stamp) {
  std::lock_guard<std::mutex> lock(mutex_);
  vector_map_pub_.publish(ToVectorMapMsg(map, map_frame, stamp));
  markers_pub_.publish(markers_.Build(map, map_frame, stamp));
  path_pub_.publish(ToPathMsg(map.trajectory, map_frame, path_max_poses_, stamp));
  const bool changed = !last_T_base_cam_ || !last_T_base_cam_->isApprox(map.T_base_cam, 1e-12);
  if (changed) {
    static_tf_.sendTransform(
        IsometryToTransformStamped(map.T_base_cam, stamp, base_frame, refined_camera_frame));
    last_T_base_cam_ = map.T_base_cam;
  }
}

void MapPublisher::Clear(const std::string& map_frame, const ros::Time& stamp) {
  std::lock_guard<std::mutex> lock(mutex_);
  VectorMap empty;
  vector_map_pub_.publish(ToVectorMapMsg(empty, map_frame, stamp));
  markers_pub_.publish(markers_.Clear());
  path_pub_.publish(ToPathMsg({}, map_frame, path_max_poses_, stamp));
}

}  // namespace ipm_road_mapper
