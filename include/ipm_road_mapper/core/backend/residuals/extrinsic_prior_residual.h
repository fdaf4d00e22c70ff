// The accumulated extrinsic prior (extrinsic_prior.h) as a residual of the map step:
//   delta(q, t) = [ Log(q q0^-1) ; t - t0 ]
//   r = L (delta(q, t) - delta_mean)                                  (6 residuals)
// with L^T L = H, so 1/2 |r|^2 equals the prior's cost up to a constant. Log is the exact
// rotation vector (ceres::QuaternionToAngleAxis, safe for autodiff near the identity), the
// same chart the marginalization differentiates in.
// The same form with any L and mean holds chosen directions of the extrinsic
// (extrinsic_observability.h: the unobserved ones, pinned at the window's start value).
// Parameter blocks: q_base_cam[4] (Eigen x, y, z, w), t_base_cam[3].
#pragma once

#include <ceres/autodiff_cost_function.h>
#include <ceres/rotation.h>

#include <Eigen/Geometry>

#include "ipm_road_mapper/core/backend/extrinsic_prior.h"

namespace ipm_road_mapper {
namespace residuals {

class ExtrinsicPriorResidual {
 public:
  explicit ExtrinsicPriorResidual(const ExtrinsicPrior& prior)
      : q0_inv_(prior.q0().conjugate()),
        t0_(prior.t0()),
        L_(prior.SqrtInformation()),
        mean_(prior.MeanDelta()) {}
  // r = L (delta(q, t) - mean) in the chart around (q0, t0).
  ExtrinsicPriorResidual(const Eigen::Quaterniond& q0, const Eigen::Vector3d& t0,
                         const Eigen::Matrix<double, 6, 6>& L,
                         const Eigen::Matrix<double, 6, 1>& mean)
      : q0_inv_(q0.conjugate()), t0_(t0), L_(L), mean_(mean) {}

  template <typename T>
  bool operator()(const T* const q_base_cam, const T* const t_base_cam, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q(q_base_cam);
    const Eigen::Quaternion<T> dq = q * q0_inv_.cast<T>();
    const T dq_wxyz[4] = {dq.w(), dq.x(), dq.y(), dq.z()};
    Eigen::Matrix<T, 6, 1> delta;
    ceres::QuaternionToAngleAxis(dq_wxyz, delta.data());
    for (int i = 0; i < 3; ++i) delta(3 + i) = t_base_cam[i] - T(t0_(i));
    const Eigen::Matrix<T, 6, 1> r = L_.cast<T>() * (delta - mean_.cast<T>());
    for (int i = 0; i < 6; ++i) residual[i] = r(i);
    return true;
  }

  static ceres::CostFunction* Create(const ExtrinsicPrior& prior) {
    return new ceres::AutoDiffCostFunction<ExtrinsicPriorResidual, 6, 4, 3>(
        new ExtrinsicPriorResidual(prior));
  }
  static ceres::CostFunction* Create(const Eigen::Quaterniond& q0, const Eigen::Vector3d& t0,
                                     const Eigen::Matrix<double, 6, 6>& L,
                                     const Eigen::Matrix<double, 6, 1>& mean) {
    return new ceres::AutoDiffCostFunction<ExtrinsicPriorResidual, 6, 4, 3>(
        new ExtrinsicPriorResidual(q0, t0, L, mean));
  }

 private:
  Eigen::Quaterniond q0_inv_;
  Eigen::Vector3d t0_;
  Eigen::Matrix<double, 6, 6> L_;
  Eigen::Matrix<double, 6, 1> mean_;
};

}  // namespace residuals
}  // namespace ipm_road_mapper
