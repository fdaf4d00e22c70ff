// Prior on the extrinsic rotation about its rough (mounting) value, per base_link axis:
//   dq = q_base_cam * q0^-1   (the correction, expressed in base_link), w >= 0
//   r  = 2 vec(dq) ./ sigma   (~ roll, pitch, yaw of the correction / sigma) (3 residuals)
// Why per axis: on a straight drive the camera's rotation about the direction of travel
// (roll) is exactly compensated by rotating the map about the trajectory, so only a prior
// can hold it; pitch and yaw are observable and get a loose sigma.
// Parameter block: q_base_cam[4] (Eigen x, y, z, w).
#pragma once

#include <ceres/autodiff_cost_function.h>

#include <Eigen/Geometry>

namespace ipm_road_mapper {
namespace residuals {

class RotationPriorResidual {
 public:
  RotationPriorResidual(const Eigen::Quaterniond& q0, const Eigen::Vector3d& sigma_rad)
      : q0_inv_(q0.conjugate()), inv_sigma_(sigma_rad.cwiseInverse()) {}

  template <typename T>
  bool operator()(const T* const q_base_cam, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q(q_base_cam);
    Eigen::Quaternion<T> dq = q * q0_inv_.cast<T>();
    if (dq.w() < T(0)) dq.coeffs() = -dq.coeffs();
    for (int i = 0; i < 3; ++i) residual[i] = T(2.0) * dq.vec()(i) * T(inv_sigma_(i));
    return true;
  }

  static ceres::CostFunction* Create(const Eigen::Quaterniond& q0,
                                     const Eigen::Vector3d& sigma_rad) {
    return new ceres::AutoDiffCostFunction<RotationPriorResidual, 3, 4>(
        new RotationPriorResidual(q0, sigma_rad));
  }

 private:
  Eigen::Quaterniond q0_inv_;
  Eigen::Vector3d inv_sigma_;
};

}  // namespace residuals
}  // namespace ipm_road_mapper
