// The nodelet's pose outputs (REP-105), per used frame from the mapping thread:
// ~corrected_odom, the newest frame's corrected pose with its covariance in the map frame,
// and, with ros/publish_map_to_odom, the correction as the tf map_frame -> odom_frame at the
// frame's stamp, so that map_frame -> base_link (through the odometry source's
// odom -> base_link) is the corrected pose. The message builders are pure functions.
#pragma once

#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/Odometry.h>
#include <ros/node_handle.h>
#include <ros/publisher.h>
#include <tf2_ros/transform_broadcaster.h>

#include "ipm_road_mapper/ros/mapping_worker.h"

namespace ipm_road_mapper {

// ~corrected_odom for one frame: header (stamp, map_frame), child base_frame, the corrected
// pose and its covariance (row-major x y z, rotation about the map axes); twist unset.
nav_msgs::Odometry ToCorrectedOdometry(const FrameOutputs& outputs, const ros::Time& stamp);

// The correction as the transform map_frame -> odom_frame at `stamp`.
geometry_msgs::TransformStamped ToMapToOdom(const FrameOutputs& outputs, const ros::Time& stamp);

class PosePublisher {
 public:
  // Advertises ~corrected_odom on `private_nh`; broadcasts map -> odom when publish_map_to_odom.
  PosePublisher(ros::NodeHandle& private_nh, bool publish_map_to_odom);

  // Publishes the outputs of the frame stamped `stamp`.
  void Publish(const FrameOutputs& outputs, const ros::Time& stamp);

 private:
  ros::Publisher corrected_odom_pub_;
  bool publish_map_to_odom_;
  tf2_ros::TransformBroadcaster tf_broadcaster_;
};

}  // namespace ipm_road_mapper
