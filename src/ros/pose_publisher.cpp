#include "ipm_road_mapper/ros/pose_publisher.h"

#include "ipm_road_mapper/ros/msg_conversion.h"

namespace ipm_road_mapper {

nav_msgs::Odometry ToCorrectedOdometry(const FrameOutputs& outputs, const ros::Time& stamp) {
  nav_msgs::Odometry odom;
  odom.header.stamp = stamp;
  odom.header.frame_id = outputs.map_frame;
  odom.child_frame_id = outputs.base_frame;
  odom.pose.pose = IsometryToPose(outputs.T_map_base);
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 6; ++c)
      odom.pose.covariance[6 * r + c] = outputs.T_map_base_covariance(r, c);
  }
  return odom;
}

geometry_msgs::TransformStamped ToMapToOdom(const FrameOutputs& outputs, const ros::Time& stamp) {
  return IsometryToTransformStamped(outputs.T_map_odom, stamp, outputs.map_frame,
                                    outputs.odom_frame);
}

PosePublisher::PosePublisher(ros::NodeHandle& private_nh, bool publish_map_to_odom)
    : corrected_odom_pub_(private_nh.advertise<nav_msgs::Odometry>("corrected_odom", 10)),
      publish_map_to_odom_(publish_map_to_odom) {}

void PosePublisher::Publish(const FrameOutputs& outputs, const ros::Time& stamp) {
  corrected_odom_pub_.publish(ToCorrectedOdometry(outputs, stamp));
  if (publish_map_to_odom_) tf_broadcaster_.sendTransform(ToMapToOdom(outputs, stamp));
}

}  // namespace ipm_road_mapper
