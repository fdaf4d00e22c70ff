#include "ipm_road_mapper/core/geometry/rigid_transform.h"

#include <algorithm>
#include <cmath>

namespace ipm_road_mapper {
namespace {

Eigen::Matrix3d Hat(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

// Left Jacobian of SO(3), V(omega) = I + (1 - cos t)/t^2 W + (t - sin t)/t^3 W^2 with
// W = hat(omega), t = |omega|. It maps the twist's rho to the translation: t = V rho.
Eigen::Matrix3d LeftJacobianSo3(const Eigen::Vector3d& omega) {
  const double theta = omega.norm();
  const Eigen::Matrix3d W = Hat(omega);
  const double t2 = theta * theta;
  // Both coefficients cancel catastrophically for small theta when written as above (at
  // theta = 1e-8, 1 - cos(theta) rounds to 0, dropping the first-order term). Instead,
  // (1 - cos t)/t^2 = 2 sin^2(t/2)/t^2, which has no cancellation, and (t - sin t)/t^3 uses
  // its Taylor series below 1e-2 (truncation error < 1e-17).
  if (theta < 1e-12) return Eigen::Matrix3d::Identity() + 0.5 * W + W * W / 6.0;
  const double half_sinc = std::sin(0.5 * theta) / (0.5 * theta);
  const double a = 0.5 * half_sinc * half_sinc;
  const double b = theta < 1e-2 ? 1.0 / 6.0 - t2 / 120.0 + t2 * t2 / 5040.0
                                : (theta - std::sin(theta)) / (t2 * theta);
  return Eigen::Matrix3d::Identity() + a * W + b * W * W;
}

}  // namespace

Eigen::Matrix3d ExpSo3(const Eigen::Vector3d& omega) {
  const double theta = omega.norm();
  if (theta < 1e-12) return Eigen::Matrix3d::Identity() + Hat(omega);
  return Eigen::AngleAxisd(theta, omega / theta).toRotationMatrix();
}

Eigen::Vector3d LogSo3(const Eigen::Matrix3d& R) {
  const Eigen::AngleAxisd aa(R);
  return aa.angle() * aa.axis();
}

Eigen::Isometry3d ExpSe3(const Vector6d& xi) {
  const Eigen::Vector3d rho = xi.head<3>();
  const Eigen::Vector3d omega = xi.tail<3>();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = ExpSo3(omega);
  T.translation() = LeftJacobianSo3(omega) * rho;
  return T;
}

Vector6d LogSe3(const Eigen::Isometry3d& T) {
  const Eigen::Vector3d omega = LogSo3(T.linear());
  Vector6d xi;
  xi.head<3>() = LeftJacobianSo3(omega).inverse() * T.translation();
  xi.tail<3>() = omega;
  return xi;
}

Eigen::Isometry3d InterpolateSe3(const Eigen::Isometry3d& T_a, const Eigen::Isometry3d& T_b,
                                 double alpha) {
  return T_a * ExpSe3(alpha * LogSe3(T_a.inverse() * T_b));
}

double RotationAngleBetween(const Eigen::Isometry3d& T_a, const Eigen::Isometry3d& T_b) {
  return LogSo3(T_a.linear().transpose() * T_b.linear()).norm();
}

Eigen::Matrix3d RotationFromRpy(double roll, double pitch, double yaw) {
  return (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

Eigen::Vector3d RpyFromRotation(const Eigen::Matrix3d& R) {
  // R = Rz(y) Ry(p) Rx(r): R(2,0) = -sin p, R(2,1) = cos p sin r, R(1,0) = sin y cos p.
  const double pitch = std::asin(std::clamp(-R(2, 0), -1.0, 1.0));
  const double roll = std::atan2(R(2, 1), R(2, 2));
  const double yaw = std::atan2(R(1, 0), R(0, 0));
  return {roll, pitch, yaw};
}

bool IsValidTransform(const Eigen::Isometry3d& T) {
  if (!T.matrix().allFinite()) return false;
  const Eigen::Matrix3d R = T.linear();
  return (R.transpose() * R - Eigen::Matrix3d::Identity()).norm() < 1e-6 &&
         std::abs(R.determinant() - 1.0) < 1e-6;
}

const char* ToString(PoseLookupStatus status) {
  switch (status) {
    case PoseLookupStatus::kOk:
      return "ok";
    case PoseLookupStatus::kEmpty:
      return "no_odometry";
    case PoseLookupStatus::kBeforeFirst:
      return "before_first_odometry";
    case PoseLookupStatus::kAfterLast:
      return "after_last_odometry";
    case PoseLookupStatus::kGapTooLarge:
      return "odometry_gap";
    case PoseLookupStatus::kInvalidStamp:
      return "invalid_stamp";
  }
  return "unknown";
}

PoseBuffer::PoseBuffer(double extrapolation_tolerance_s, double max_gap_s, std::size_t capacity)
    : extrapolation_tolerance_s_(extrapolation_tolerance_s),
      max_gap_s_(max_gap_s),
      capacity_(std::max<std::size_t>(capacity, 2)) {}

bool PoseBuffer::Add(const StampedPose& pose) {
  if (!std::isfinite(pose.stamp) || !IsValidTransform(pose.T_map_base)) return false;
  if (!poses_.empty() && pose.stamp <= poses_.back().stamp) return false;
  poses_.push_back(pose);
  if (poses_.size() > capacity_) poses_.erase(poses_.begin());
  return true;
}

PoseLookupStatus PoseBuffer::Lookup(double stamp, Eigen::Isometry3d* T_map_base) const {
  if (poses_.empty()) return PoseLookupStatus::kEmpty;
  // A NaN stamp fails every comparison below; the bracketing search would then run past
  // the end of the buffer.
  if (std::isnan(stamp)) return PoseLookupStatus::kInvalidStamp;
  if (stamp <= poses_.front().stamp) {
    if (poses_.front().stamp - stamp > extrapolation_tolerance_s_) {
      return PoseLookupStatus::kBeforeFirst;
    }
    *T_map_base = poses_.front().T_map_base;
    return PoseLookupStatus::kOk;
  }
  if (stamp >= poses_.back().stamp) {
    if (stamp - poses_.back().stamp > extrapolation_tolerance_s_) {
      return PoseLookupStatus::kAfterLast;
    }
    *T_map_base = poses_.back().T_map_base;
    return PoseLookupStatus::kOk;
  }
  const auto after = std::upper_bound(poses_.begin(), poses_.end(), stamp,
                                      [](double s, const StampedPose& p) { return s < p.stamp; });
  const auto before = after - 1;
  const double dt = after->stamp - before->stamp;
  if (dt > max_gap_s_) return PoseLookupStatus::kGapTooLarge;
  const double alpha = (stamp - before->stamp) / dt;
  *T_map_base = InterpolateSe3(before->T_map_base, after->T_map_base, alpha);
  return PoseLookupStatus::kOk;
}

}  // namespace ipm_road_mapper
