// What the back end knows about the camera extrinsic T_base_cam from data that has left
// the sliding window, as a Gaussian on its tangent around a fixed point (q0, t0):
//   delta = [ Log(q q0^-1) ; t - t0 ]       (rotation: the correction in base_link, rad; m)
//   cost(delta) = 1/2 delta^T H delta + b^T delta + const
// The extrinsic is one constant of the whole drive, but each window sees it for two
// seconds: estimated per window it random-walks (0.26 deg of roll from a perfect start on
// the ideal drive). So every marking and lane stretch that retires from the window leaves
// its information here (extrinsic_marginalization.h: its points marginalized by the Schur
// complement), and each window's map step adds this prior instead of starting afresh. The
// mounting prior (t_0 of the paper, and a loose hold on the mounting angles) is the first
// term, so it is counted once, and it is never forgotten.
//
// Bounded memory: the retired information is a marginal that forgets. Each Add first scales
// what is there by lambda = 1 - 1 / memory_factors (exponential forgetting, Kalman-style),
// so the prior holds about the last memory_factors batches: a batch linearized early, at the
// rough extrinsic and with poses it had not yet corrected, fades instead of locking its bias
// in (a plain sum made the x/y lever arm wander 3-4 cm on most drives). memory_factors <= 0:
// no forgetting (a plain sum).
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

namespace ipm_road_mapper {

// Information of one batch of retired measurements about delta, linearized at delta_lin:
//   1/2 (delta - delta_lin)^T H (delta - delta_lin) + g^T (delta - delta_lin).
struct ExtrinsicFactor {
  Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> g = Eigen::Matrix<double, 6, 1>::Zero();
  Eigen::Matrix<double, 6, 1> delta_lin = Eigen::Matrix<double, 6, 1>::Zero();
};

// The accumulated Gaussian (see the file comment).
class ExtrinsicPrior {
 public:
  ExtrinsicPrior() = default;
  // Centered on T_base_cam_0 (the rough extrinsic) with per-axis sigmas of the rotation
  // (base_link roll, pitch, yaw, rad) and the translation (m): the mounting prior.
  ExtrinsicPrior(const Eigen::Isometry3d& T_base_cam_0, const Eigen::Vector3d& sigma_rot_rad,
                 const Eigen::Vector3d& sigma_trans_m, double memory_factors = 0.0);

  // Forgets (see the file comment), then adds a batch's information.
  void Add(const ExtrinsicFactor& factor);

  // delta of an extrinsic, and the extrinsic of a delta (around q0, t0).
  Eigen::Matrix<double, 6, 1> DeltaOf(const Eigen::Isometry3d& T_base_cam) const;
  Eigen::Isometry3d FromDelta(const Eigen::Matrix<double, 6, 1>& delta) const;

  // The minimizer of the cost, and the cost's square root: cost = 1/2 |L (delta - mean)|^2.
  Eigen::Matrix<double, 6, 1> MeanDelta() const;
  Eigen::Matrix<double, 6, 6> SqrtInformation() const;

  const Eigen::Quaterniond& q0() const { return q0_; }
  const Eigen::Vector3d& t0() const { return t0_; }
  // The whole information (mounting + retired) and the mounting part alone.
  Eigen::Matrix<double, 6, 6> H() const { return H_mount_ + H_; }
  const Eigen::Matrix<double, 6, 6>& H_mount() const { return H_mount_; }
  int factors() const { return factors_; }
  double memory_factors() const { return memory_factors_; }

 private:
  Eigen::Quaterniond q0_ = Eigen::Quaterniond::Identity();
  Eigen::Vector3d t0_ = Eigen::Vector3d::Zero();
  Eigen::Matrix<double, 6, 6> H_mount_ = Eigen::Matrix<double, 6, 6>::Zero();  // mean: delta 0
  Eigen::Matrix<double, 6, 6> H_ = Eigen::Matrix<double, 6, 6>::Zero();        // retired batches
  Eigen::Matrix<double, 6, 1> b_ = Eigen::Matrix<double, 6, 1>::Zero();
  int factors_ = 0;
  double memory_factors_ = 0.0;
};

}  // namespace ipm_road_mapper
