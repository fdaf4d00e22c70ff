// Which directions of the camera extrinsic a window's data observes (observability-aware
// self-calibration, Schneider et al., RA-L 2019: update only the well-conditioned directions
// of the calibration, truncated-SVD style, and hold the others at their prior).
//
// Coordinates: the extrinsic prior's chart (extrinsic_prior.h),
//   delta = [ phi ; dt ],  q = Exp(phi) q0 (phi: rotation vector in base_link, rad), t = t0 + dt,
// so index 0..5 = roll, pitch, yaw (about base_link x, y, z), x, y, z (m).
//
// The data's information H (6x6: the Gauss-Newton Hessian of the window's measurements, its
// map points marginalized by the Schur complement) is compared with the mounting prior's in
// whitened coordinates, H_w = S H S with S = diag(prior sigmas): an eigenvalue lambda of H_w is
// how many times the data knows that combination better than the prior does. A direction
// is observed when lambda >= min_information_ratio. Height and pitch come out as one
// eigenvector when the ground constrains their combination (the homography) and not each
// alone; the x/y lever arm becomes observed only when turns make the data see it.
#pragma once

#include <ceres/problem.h>

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

namespace ipm_road_mapper {

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Vector6d = Eigen::Matrix<double, 6, 1>;

// What one window's data says about the extrinsic, and what the update may touch.
struct ExtrinsicObservability {
  Matrix6d information = Matrix6d::Zero();  // data information H (chart, see above)
  // Eigen-decomposition of the whitened information: columns of basis_whitened are its
  // eigenvectors (ascending eigenvalues), observed[k] whether column k is observed.
  Vector6d eigenvalues = Vector6d::Zero();
  Matrix6d basis_whitened = Matrix6d::Identity();
  std::array<bool, 6> observed{};
  int rank = 0;  // number of observed directions
  // Per axis (roll, pitch, yaw, x, y, z): at least half of the whitened unit axis lies in
  // the observed subspace (|V_o^T e_i|^2 >= 0.5).
  std::array<bool, 6> axis_observed{};
  // The information restricted to the observed directions (chart): S^-1 V_o L_o V_o^T S^-1.
  Matrix6d ObservedInformation() const;
  // Rows (chart) that pin the unobserved directions: sqrt(weight) v_u^T S^-1, one per
  // unobserved eigenvector, zero rows for the observed ones (L^T L is the hold's Hessian).
  Matrix6d UnobservedHoldSqrtInformation(double weight) const;
  // rank and axis_observed from `observed` (after a check changed it, e.g. the
  // cross-validation of window_extrinsic_validation.h).
  void CountObserved();
  Vector6d prior_sigma = Vector6d::Ones();  // S's diagonal
};

// Decomposes `information` (chart) against the prior sigmas (see the file comment).
ExtrinsicObservability AnalyzeObservability(const Matrix6d& information,
                                            const Vector6d& prior_sigma,
                                            double min_information_ratio);

// The Gauss-Newton information of `problem`'s residual blocks, except `excluded`, on the
// extrinsic blocks (q_base_cam with ceres::EigenQuaternionManifold, t_base_cam), every other
// variable block marginalized (Schur complement), in the chart's coordinates. Loss functions
// are applied at the current values. Zero when the extrinsic is not a variable of `problem`.
Matrix6d ExtrinsicInformation(ceres::Problem* problem, double* q_base_cam, double* t_base_cam,
                              const std::vector<ceres::ResidualBlockId>& excluded);

// The observed axes by name, e.g. "roll pitch yaw z"; "none" when none.
std::string ObservedAxesText(const std::array<bool, 6>& observed);

// The mounting prior's sigmas as one chart vector: rotation (rad), then translation (m).
Vector6d PriorSigma(const Eigen::Vector3d& sigma_rot_rad, const Eigen::Vector3d& sigma_trans_m);

}  // namespace ipm_road_mapper
