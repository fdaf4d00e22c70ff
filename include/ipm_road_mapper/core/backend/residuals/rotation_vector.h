// The rotation vector (SO(3) log) of a unit quaternion for autodiff residuals, taken the short
// way round: the angle-axis of dq or of -dq, whichever has w >= 0 (the same rotation), so
// the angle is at most pi. ceres::QuaternionToAngleAxis is exact and smooth near the
// identity, where the motion and twist priors evaluate it.
#pragma once

#include <ceres/rotation.h>

#include <Eigen/Geometry>

namespace ipm_road_mapper {
namespace residuals {

// log(dq) in radians (axis times angle).
template <typename T>
Eigen::Matrix<T, 3, 1> RotationVector(Eigen::Quaternion<T> dq) {
  if (dq.w() < T(0)) dq.coeffs() = -dq.coeffs();  // the short way round
  const T wxyz[4] = {dq.w(), dq.x(), dq.y(), dq.z()};
  Eigen::Matrix<T, 3, 1> angle_axis;
  ceres::QuaternionToAngleAxis(wxyz, angle_axis.data());
  return angle_axis;
}

}  // namespace residuals
}  // namespace ipm_road_mapper
