#include "ipm_road_mapper/core/mapper/pose_extrapolator.h"

#include <ceres/ceres.h>

#include <algorithm>

#include "ipm_road_mapper/core/backend/residuals/constant_twist_prior_residual.h"
#include "ipm_road_mapper/core/backend/residuals/pose_prior_residual.h"

namespace ipm_road_mapper {
namespace {

// The horizon of the tail's problem, 1.5 s at 20 Hz. Under the constant-twist prior a curve
// costs nothing, so the horizon is set by how much jitter it averages: the public_road probe
// (300 frames, ~corrected_odom against the input's error, solves one frame behind) 0.60x at
// 15 frames, 0.575x at 20, 0.554x at 30, 0.552x at 40 (live timing: 0.557-0.563x at 30,
// 0.554-0.561x at 40). Under the map-frame motion prior it was 20: a longer tail bent the
// newest pose on curves (5 cm at 20 frames, 12 cm at 40 on a 200 m curve at 10 m/s).
constexpr std::size_t kHorizonFrames = 30;

// A pose as Ceres blocks: quaternion (x, y, z, w) and translation.
struct Blocks {
  Eigen::Quaterniond q;
  Eigen::Vector3d t;
  explicit Blocks(const Eigen::Isometry3d& T) : q(T.linear()), t(T.translation()) { q.normalize(); }
  Eigen::Isometry3d ToIsometry() const {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = q.normalized().toRotationMatrix();
    T.translation() = t;
    return T;
  }
};

}  // namespace

Eigen::Isometry3d ExtrapolateNewestPose(const std::vector<FrameRecord>& frames, std::size_t solved,
                                        const Eigen::Isometry3d& T_map_odom,
                                        const BackendOptions& options) {
  const std::size_t newest = frames.size() - 1;
  const Eigen::Isometry3d carried = T_map_odom * frames[newest].T_map_base_odom;
  const std::size_t span = static_cast<std::size_t>(options.window_frames);
  if (!options.motion_prior || solved == 0 || solved >= newest || newest - solved >= span) {
    return carried;
  }
  // The last kHorizonFrames frames (at least two solved ones), each a free pose with its
  // prior: the solved pose up to `solved`, the carried odometry after it. Holding the two
  // newest solved frames as data instead took the velocity from their difference, i.e. from
  // two window-edge estimates 50 ms apart: the live ~corrected_odom of the public_road
  // rostest was 0.76x the input's error, 0.63x with this tail under the map-frame motion
  // prior, ~0.56x under the constant-twist one.
  const std::size_t first = std::min(solved - 1, newest + 1 - std::min(kHorizonFrames, newest + 1));
  std::vector<Eigen::Isometry3d> priors;
  for (std::size_t i = first; i <= newest; ++i) {
    priors.push_back(i <= solved ? frames[i].T_map_base : T_map_odom * frames[i].T_map_base_odom);
  }
  std::vector<Blocks> poses;
  for (const Eigen::Isometry3d& prior : priors) poses.emplace_back(prior);
  ceres::Problem problem;
  for (std::size_t k = 0; k < poses.size(); ++k) {
    problem.AddResidualBlock(
        residuals::PosePriorResidual::Create(priors[k], options.pose_prior_sigma_trans_m,
                                             options.pose_prior_sigma_rot_rad),
        nullptr, poses[k].q.coeffs().data(), poses[k].t.data());
    problem.SetManifold(poses[k].q.coeffs().data(), new ceres::EigenQuaternionManifold);
  }
  for (std::size_t k = 1; k + 1 < poses.size(); ++k) {
    const double dt_a = frames[first + k].stamp - frames[first + k - 1].stamp;
    const double dt_b = frames[first + k + 1].stamp - frames[first + k].stamp;
    if (!(dt_a > 0.0) || !(dt_b > 0.0)) return carried;
    problem.AddResidualBlock(
        residuals::ConstantTwistPriorResidual::Create(dt_a, dt_b, options.motion_sigma_acc_mps2,
                                                      options.motion_sigma_angular_acc_radps2),
        nullptr, poses[k - 1].q.coeffs().data(), poses[k - 1].t.data(), poses[k].q.coeffs().data(),
        poses[k].t.data(), poses[k + 1].q.coeffs().data(), poses[k + 1].t.data());
  }
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;  // a banded system
  solver.max_num_iterations = options.max_iterations;
  solver.num_threads = 1;
  solver.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &problem, &summary);
  if (!summary.IsSolutionUsable()) return carried;
  return poses.back().ToIsometry();
}

}  // namespace ipm_road_mapper
