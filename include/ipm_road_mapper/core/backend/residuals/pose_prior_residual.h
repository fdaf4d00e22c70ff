// Prior of a vehicle pose on its odometry (paper, "Pose Update": || Tbar_k^-1 T_k ||^2).
// With the error Delta = Tbar_k^-1 T_k = (dR, dt):
//   r = [ dt / sigma_trans ; 2 vec(dq) / sigma_rot ]                   (6 residuals)
// where dq is the quaternion of dR with non-negative w, so 2 vec(dq) ~ Log(dR) for small
// angles (the rotation vector) and the residual is smooth for autodiff. sigma_trans and
// sigma_rot are per axis (x, y, z of base_link), so the prior can be looser along the
// direction odometry drifts most.
// Parameter blocks: q_map_base[4], t_map_base[3].
#pragma once

#include <ceres/autodiff_cost_function.h>

#include <Eigen/Geometry>

namespace ipm_road_mapper {
namespace residuals {

class PosePriorResidual {
 public:
  PosePriorResidual(const Eigen::Isometry3d& T_map_base_prior, const Eigen::Vector3d& sigma_trans_m,
                    const Eigen::Vector3d& sigma_rot_rad)
      : q_prior_inv_(Eigen::Quaterniond(T_map_base_prior.linear()).conjugate()),
        t_prior_(T_map_base_prior.translation()),
        inv_sigma_trans_(sigma_trans_m.cwiseInverse()),
        inv_sigma_rot_(sigma_rot_rad.cwiseInverse()) {}

  template <typename T>
  bool operator()(const T* const q_map_base, const T* const t_map_base, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q(q_map_base);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t(t_map_base);
    const Eigen::Quaternion<T> q_inv = q_prior_inv_.cast<T>();
    // Delta = Tbar^-1 T: dR = Rbar^T R, dt = Rbar^T (t - tbar), in the prior's base frame.
    Eigen::Quaternion<T> dq = q_inv * q;
    if (dq.w() < T(0)) dq.coeffs() = -dq.coeffs();
    const Eigen::Matrix<T, 3, 1> dt = q_inv * (t - t_prior_.cast<T>());
    for (int i = 0; i < 3; ++i) {
      residual[i] = dt(i) * T(inv_sigma_trans_(i));
      residual[3 + i] = T(2.0) * dq.vec()(i) * T(inv_sigma_rot_(i));
    }
    return true;
  }

  static ceres::CostFunction* Create(const Eigen::Isometry3d& T_map_base_prior,
                                     const Eigen::Vector3d& sigma_trans_m,
                                     const Eigen::Vector3d& sigma_rot_rad) {
    return new ceres::AutoDiffCostFunction<PosePriorResidual, 6, 4, 3>(
        new PosePriorResidual(T_map_base_prior, sigma_trans_m, sigma_rot_rad));
  }

 private:
  Eigen::Quaterniond q_prior_inv_;
  Eigen::Vector3d t_prior_;
  Eigen::Vector3d inv_sigma_trans_;
  Eigen::Vector3d inv_sigma_rot_;
};

}  // namespace residuals
}  // namespace ipm_road_mapper
