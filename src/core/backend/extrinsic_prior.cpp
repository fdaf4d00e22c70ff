#include "ipm_road_mapper/core/backend/extrinsic_prior.h"

#include <Eigen/Eigenvalues>
#include <algorithm>

#include "ipm_road_mapper/core/geometry/rigid_transform.h"

namespace ipm_road_mapper {

ExtrinsicPrior::ExtrinsicPrior(const Eigen::Isometry3d& T_base_cam_0,
                               const Eigen::Vector3d& sigma_rot_rad,
                               const Eigen::Vector3d& sigma_trans_m, double memory_factors)
    : q0_(Eigen::Quaterniond(T_base_cam_0.linear()).normalized()),
      t0_(T_base_cam_0.translation()),
      memory_factors_(memory_factors) {
  for (int i = 0; i < 3; ++i) {
    H_mount_(i, i) = 1.0 / (sigma_rot_rad(i) * sigma_rot_rad(i));
    H_mount_(3 + i, 3 + i) = 1.0 / (sigma_trans_m(i) * sigma_trans_m(i));
  }
}

void ExtrinsicPrior::Add(const ExtrinsicFactor& factor) {
  if (memory_factors_ > 0.0) {
    const double lambda = std::max(0.0, 1.0 - 1.0 / memory_factors_);
    H_ *= lambda;
    b_ *= lambda;
  }
  // 1/2 (d - l)^T H (d - l) + g^T (d - l) = 1/2 d^T H d + (g - H l)^T d + const.
  H_ += factor.H;
  b_ += factor.g - factor.H * factor.delta_lin;
  ++factors_;
}

Eigen::Matrix<double, 6, 1> ExtrinsicPrior::DeltaOf(const Eigen::Isometry3d& T_base_cam) const {
  Eigen::Matrix<double, 6, 1> delta;
  delta.head<3>() = LogSo3(T_base_cam.linear() * q0_.toRotationMatrix().transpose());
  delta.tail<3>() = T_base_cam.translation() - t0_;
  return delta;
}

Eigen::Isometry3d ExtrinsicPrior::FromDelta(const Eigen::Matrix<double, 6, 1>& delta) const {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = ExpSo3(delta.head<3>()) * q0_.toRotationMatrix();
  T.translation() = t0_ + delta.tail<3>();
  return T;
}

Eigen::Matrix<double, 6, 1> ExtrinsicPrior::MeanDelta() const { return H().ldlt().solve(-b_); }

Eigen::Matrix<double, 6, 6> ExtrinsicPrior::SqrtInformation() const {
  // H = V diag(lambda) V^T -> L = diag(sqrt(lambda)) V^T, so L^T L = H (also for a
  // semi-definite H, where a Cholesky factor would not exist).
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eigen(H());
  const Eigen::Matrix<double, 6, 1> roots = eigen.eigenvalues().cwiseMax(0.0).cwiseSqrt();
  return roots.asDiagonal() * eigen.eigenvectors().transpose();
}

}  // namespace ipm_road_mapper
