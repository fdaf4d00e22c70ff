// The ROS bridge: ROS messages <-> the core's types (CameraIntrinsics, StampedPose,
// Eigen::Isometry3d, the 16UC1 mask as cv::Mat). Small pure functions, shared by the
// nodelet and the offline tools. A bad message never throws: the converters that can fail
// return an empty string on success and otherwise one line saying what is wrong.
#pragma once

#include <geometry_msgs/Point.h>
#include <geometry_msgs/Pose.h>
#include <geometry_msgs/Transform.h>
#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/Odometry.h>
#include <ros/time.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <string>

#include "ipm_road_mapper/core/geometry/pinhole_camera.h"
#include "ipm_road_mapper/core/geometry/rigid_transform.h"

namespace ipm_road_mapper {

// sensor_msgs/CameraInfo -> intrinsics (K and D). Accepts distortion_model "plumb_bob" (D
// empty or 5 values) and "" with an empty or all-zero D; any other model (e.g.
// rational_polynomial, equidistant), a plumb_bob D of another length, a non-finite K/D, a
// binning other than 0/1 or a region of interest smaller than the image is an error.
std::string CameraInfoToIntrinsics(const sensor_msgs::CameraInfo& msg,
                                   CameraIntrinsics* intrinsics);

// Intrinsics -> sensor_msgs/CameraInfo (plumb_bob, P = [K | 0], R = I); header left empty.
sensor_msgs::CameraInfo IntrinsicsToCameraInfo(const CameraIntrinsics& intrinsics);

// geometry_msgs/Quaternion -> rotation. Accepts a quaternion whose norm is within 1e-3 of 1
// (normalizing it); a zero, non-finite or far-from-unit one is an error.
std::string QuaternionToRotation(const geometry_msgs::Quaternion& msg, Eigen::Quaterniond* q);

// geometry_msgs/Transform -> T (maps child-frame points into the parent frame).
std::string TransformToIsometry(const geometry_msgs::Transform& msg, Eigen::Isometry3d* T);

// T -> geometry_msgs/Transform.
geometry_msgs::Transform IsometryToTransform(const Eigen::Isometry3d& T);

// T_parent_child -> a TransformStamped from `parent_frame` to `child_frame` at `stamp`.
geometry_msgs::TransformStamped IsometryToTransformStamped(const Eigen::Isometry3d& T_parent_child,
                                                           const ros::Time& stamp,
                                                           const std::string& parent_frame,
                                                           const std::string& child_frame);

// Eigen point <-> geometry_msgs/Point.
geometry_msgs::Point ToPointMsg(const Eigen::Vector3d& p);
inline Eigen::Vector3d FromPointMsg(const geometry_msgs::Point& p) { return {p.x, p.y, p.z}; }

// geometry_msgs/Pose -> T (pose of the body in the reference frame).
std::string PoseToIsometry(const geometry_msgs::Pose& msg, Eigen::Isometry3d* T);

// T -> geometry_msgs/Pose.
geometry_msgs::Pose IsometryToPose(const Eigen::Isometry3d& T);

// nav_msgs/Odometry -> the pose of child_frame_id (base_link) in header.frame_id at the
// header stamp (T_map_base; the twist and covariances are not used).
std::string OdometryToStampedPose(const nav_msgs::Odometry& msg, StampedPose* pose);

// Instance mask message -> CV_16UC1 cv::Mat that owns its pixels (one copy, so the frame can
// wait in a queue after the message is gone; byte order fixed when is_bigendian differs
// from the host). Encodings "16UC1" and "mono16" only; any other encoding is an error that
// names it. Sizes against the camera are checked later by the core (ValidateMask).
std::string ImageToMask(const sensor_msgs::Image& msg, cv::Mat* mask);

// CV_16UC1 mask -> sensor_msgs/Image with encoding 16UC1 (host byte order); header empty.
// Any other cv::Mat type gives an empty image (width and height 0).
sensor_msgs::Image MaskToImage(const cv::Mat& mask);

// ros::Time <-> seconds as the core counts them.
inline double ToSeconds(const ros::Time& stamp) { return stamp.toSec(); }
inline ros::Time FromSeconds(double seconds) { return ros::Time(seconds); }

}  // namespace ipm_road_mapper
