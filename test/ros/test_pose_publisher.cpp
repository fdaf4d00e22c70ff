// The pose outputs' messages (pose_publisher.h): ~corrected_odom carries the corrected pose
// and its covariance row-major in the map frame; map -> odom is the correction between the
// configured frames, and composing it with the odometry gives the corrected pose.
#include <gtest/gtest.h>

#include "ipm_road_mapper/ros/msg_conversion.h"
#include "ipm_road_mapper/ros/pose_publisher.h"

namespace ipm_road_mapper {
namespace {

FrameOutputs SomeOutputs() {
  FrameOutputs o;
  o.map_frame = "map";
  o.odom_frame = "odom";
  o.base_frame = "base_link";
  o.T_map_odom =
      Eigen::Translation3d(0.3, -0.2, 0.0) * Eigen::AngleAxisd(0.01, Eigen::Vector3d::UnitZ());
  const Eigen::Isometry3d T_odom_base(Eigen::Translation3d(50.0, 4.0, 0.1) *
                                      Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()));
  o.T_map_base = o.T_map_odom * T_odom_base;
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 6; ++c)
      o.T_map_base_covariance(r, c) = r == c ? 0.01 * (r + 1) : 0.001 * (r + c);
  }
  return o;
}

TEST(PosePublisher, CorrectedOdometryCarriesPoseCovarianceAndFrames) {
  const FrameOutputs o = SomeOutputs();
  const nav_msgs::Odometry msg = ToCorrectedOdometry(o, ros::Time(12.5));
  EXPECT_EQ(msg.header.frame_id, "map");
  EXPECT_EQ(msg.child_frame_id, "base_link");
  EXPECT_EQ(msg.header.stamp, ros::Time(12.5));
  Eigen::Isometry3d T;
  ASSERT_EQ(PoseToIsometry(msg.pose.pose, &T), "");
  EXPECT_TRUE(T.isApprox(o.T_map_base, 1e-9));
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 6; ++c)
      EXPECT_EQ(msg.pose.covariance[6 * r + c], o.T_map_base_covariance(r, c));
  }
}

TEST(PosePublisher, MapToOdomComposedWithTheOdometryIsTheCorrectedPose) {
  const FrameOutputs o = SomeOutputs();
  const geometry_msgs::TransformStamped tf = ToMapToOdom(o, ros::Time(12.5));
  EXPECT_EQ(tf.header.frame_id, "map");
  EXPECT_EQ(tf.child_frame_id, "odom");
  EXPECT_EQ(tf.header.stamp, ros::Time(12.5));
  Eigen::Isometry3d T_map_odom;
  ASSERT_EQ(TransformToIsometry(tf.transform, &T_map_odom), "");
  const Eigen::Isometry3d T_odom_base = o.T_map_odom.inverse() * o.T_map_base;
  EXPECT_TRUE((T_map_odom * T_odom_base).isApprox(o.T_map_base, 1e-9));
}

}  // namespace
}  // namespace ipm_road_mapper
