#include "ipm_road_mapper/ros/msg_conversion.h"

#include <sensor_msgs/image_encodings.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>

namespace ipm_road_mapper {
namespace {

constexpr double kQuaternionNormTolerance = 1e-3;

bool AllFinite(const double* values, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(values[i])) return false;
  }
  return true;
}

bool HostIsBigEndian() {
  const std::uint16_t probe = 1;
  std::uint8_t first_byte = 0;
  std::memcpy(&first_byte, &probe, 1);
  return first_byte == 0;
}

}  // namespace

geometry_msgs::Point ToPointMsg(const Eigen::Vector3d& p) {
  geometry_msgs::Point msg;
  msg.x = p.x();
  msg.y = p.y();
  msg.z = p.z();
  return msg;
}

std::string CameraInfoToIntrinsics(const sensor_msgs::CameraInfo& msg,
                                   CameraIntrinsics* intrinsics) {
  const std::string& model = msg.distortion_model;
  const bool all_zero_d =
      std::all_of(msg.D.begin(), msg.D.end(), [](double d) { return d == 0.0; });
  if (model == "plumb_bob") {
    if (!msg.D.empty() && msg.D.size() != 5) {
      return "camera_info: plumb_bob needs 5 distortion coefficients, got " +
             std::to_string(msg.D.size());
    }
  } else if (!(model.empty() && all_zero_d)) {
    return "camera_info: unsupported distortion model '" + model +
           "' (supported: plumb_bob, or none with an empty D)";
  }
  if (!AllFinite(msg.K.data(), msg.K.size()) || !AllFinite(msg.D.data(), msg.D.size())) {
    return "camera_info: K or D is not finite";
  }
  if (msg.binning_x > 1 || msg.binning_y > 1) {
    return "camera_info: binning is not supported (masks must be full resolution)";
  }
  const auto& roi = msg.roi;
  if ((roi.width != 0 && roi.width != msg.width) || (roi.height != 0 && roi.height != msg.height) ||
      roi.x_offset != 0 || roi.y_offset != 0) {
    return "camera_info: a region of interest is not supported (masks must be full resolution)";
  }
  CameraIntrinsics out;
  out.width = static_cast<int>(msg.width);
  out.height = static_cast<int>(msg.height);
  out.fx = msg.K[0];
  out.cx = msg.K[2];
  out.fy = msg.K[4];
  out.cy = msg.K[5];
  if (msg.D.size() == 5) {
    for (int i = 0; i < 5; ++i) out.distortion[i] = msg.D[i];
  }
  *intrinsics = out;
  return "";
}

sensor_msgs::CameraInfo IntrinsicsToCameraInfo(const CameraIntrinsics& in) {
  sensor_msgs::CameraInfo msg;
  msg.width = static_cast<std::uint32_t>(in.width);
  msg.height = static_cast<std::uint32_t>(in.height);
  msg.distortion_model = "plumb_bob";
  msg.D.assign(in.distortion.begin(), in.distortion.end());
  msg.K = {in.fx, 0.0, in.cx, 0.0, in.fy, in.cy, 0.0, 0.0, 1.0};
  msg.R = {1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0};
  msg.P = {in.fx, 0.0, in.cx, 0.0, 0.0, in.fy, in.cy, 0.0, 0.0, 0.0, 1.0, 0.0};
  return msg;
}

std::string QuaternionToRotation(const geometry_msgs::Quaternion& msg, Eigen::Quaterniond* q) {
  const Eigen::Quaterniond raw(msg.w, msg.x, msg.y, msg.z);
  if (!raw.coeffs().allFinite()) return "quaternion is not finite";
  const double norm = raw.norm();
  if (std::abs(norm - 1.0) > kQuaternionNormTolerance) {
    std::ostringstream s;
    s << "quaternion is not unit (norm " << norm << ")";
    return s.str();
  }
  *q = raw.normalized();
  return "";
}

std::string TransformToIsometry(const geometry_msgs::Transform& msg, Eigen::Isometry3d* T) {
  Eigen::Quaterniond q;
  const std::string error = QuaternionToRotation(msg.rotation, &q);
  if (!error.empty()) return "transform: " + error;
  const Eigen::Vector3d t(msg.translation.x, msg.translation.y, msg.translation.z);
  if (!t.allFinite()) return "transform: translation is not finite";
  T->setIdentity();
  T->linear() = q.toRotationMatrix();
  T->translation() = t;
  return "";
}

geometry_msgs::Transform IsometryToTransform(const Eigen::Isometry3d& T) {
  geometry_msgs::Transform msg;
  const Eigen::Quaterniond q(T.rotation());
  msg.translation.x = T.translation().x();
  msg.translation.y = T.translation().y();
  msg.translation.z = T.translation().z();
  msg.rotation.x = q.x();
  msg.rotation.y = q.y();
  msg.rotation.z = q.z();
  msg.rotation.w = q.w();
  return msg;
}

geometry_msgs::TransformStamped IsometryToTransformStamped(const Eigen::Isometry3d& T_parent_child,
                                                           const ros::Time& stamp,
                                                           const std::string& parent_frame,
                                                           const std::string& child_frame) {
  geometry_msgs::TransformStamped msg;
  msg.header.stamp = stamp;
  msg.header.frame_id = parent_frame;
  msg.child_frame_id = child_frame;
  msg.transform = IsometryToTransform(T_parent_child);
  return msg;
}

std::string PoseToIsometry(const geometry_msgs::Pose& msg, Eigen::Isometry3d* T) {
  Eigen::Quaterniond q;
  const std::string error = QuaternionToRotation(msg.orientation, &q);
  if (!error.empty()) return "pose: " + error;
  const Eigen::Vector3d t(msg.position.x, msg.position.y, msg.position.z);
  if (!t.allFinite()) return "pose: position is not finite";
  T->setIdentity();
  T->linear() = q.toRotationMatrix();
  T->translation() = t;
  return "";
}

geometry_msgs::Pose IsometryToPose(const Eigen::Isometry3d& T) {
  const geometry_msgs::Transform transform = IsometryToTransform(T);
  geometry_msgs::Pose msg;
  msg.position.x = transform.translation.x;
  msg.position.y = transform.translation.y;
  msg.position.z = transform.translation.z;
  msg.orientation = transform.rotation;
  return msg;
}

std::string OdometryToStampedPose(const nav_msgs::Odometry& msg, StampedPose* pose) {
  StampedPose out;
  out.stamp = ToSeconds(msg.header.stamp);
  const std::string error = PoseToIsometry(msg.pose.pose, &out.T_map_base);
  if (!error.empty()) return "odometry: " + error;
  *pose = out;
  return "";
}

std::string ImageToMask(const sensor_msgs::Image& msg, cv::Mat* mask) {
  namespace enc = sensor_msgs::image_encodings;
  if (msg.encoding != enc::TYPE_16UC1 && msg.encoding != enc::MONO16) {
    return "mask encoding is '" + msg.encoding + "', expected 16UC1 or mono16";
  }
  const std::size_t row_bytes = static_cast<std::size_t>(msg.width) * 2;
  if (msg.width == 0 || msg.height == 0) return "mask image is empty";
  if (msg.step < row_bytes) {
    return "mask step " + std::to_string(msg.step) +
           " is smaller than width * 2 = " + std::to_string(row_bytes);
  }
  if (msg.data.size() < static_cast<std::size_t>(msg.step) * msg.height) {
    return "mask data has " + std::to_string(msg.data.size()) +
           " bytes, expected step * height = " +
           std::to_string(static_cast<std::size_t>(msg.step) * msg.height);
  }
  // cv::Mat needs a non-const pointer; the header is only used to copy from.
  const cv::Mat view(static_cast<int>(msg.height), static_cast<int>(msg.width), CV_16UC1,
                     const_cast<std::uint8_t*>(msg.data.data()), msg.step);
  cv::Mat out = view.clone();
  if (static_cast<bool>(msg.is_bigendian) != HostIsBigEndian()) {
    for (int row = 0; row < out.rows; ++row) {
      auto* pixel = out.ptr<std::uint16_t>(row);
      for (int col = 0; col < out.cols; ++col) {
        pixel[col] = static_cast<std::uint16_t>((pixel[col] >> 8) | (pixel[col] << 8));
      }
    }
  }
  *mask = out;
  return "";
}

sensor_msgs::Image MaskToImage(const cv::Mat& mask) {
  sensor_msgs::Image msg;
  if (mask.empty() || mask.type() != CV_16UC1) return msg;
  msg.width = static_cast<std::uint32_t>(mask.cols);
  msg.height = static_cast<std::uint32_t>(mask.rows);
  msg.encoding = sensor_msgs::image_encodings::TYPE_16UC1;
  msg.is_bigendian = HostIsBigEndian();
  msg.step = msg.width * 2;
  msg.data.resize(static_cast<std::size_t>(msg.step) * msg.height);
  for (int row = 0; row < mask.rows; ++row) {
    std::memcpy(&msg.data[static_cast<std::size_t>(row) * msg.step], mask.ptr(row), msg.step);
  }
  return msg;
}

}  // namespace ipm_road_mapper
