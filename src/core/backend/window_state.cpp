#include "ipm_road_mapper/core/backend/window_state.h"

#include <algorithm>
#include <cmath>

#include "ipm_road_mapper/core/backend/residuals/corner_reprojection_residual.h"
#include "ipm_road_mapper/core/backend/residuals/motion_prior_residual.h"
#include "ipm_road_mapper/core/backend/residuals/pose_prior_residual.h"

namespace ipm_road_mapper {
namespace window_solve {

bool ProjectsNearImage(const PinholeCamera& camera, const WindowState& state, std::size_t slot,
                       const Eigen::Vector3d& p_map, double margin_px) {
  Eigen::Vector2d uv;
  if (!residuals::ProjectMapPoint(camera, state.frames[slot].q, state.frames[slot].t,
                                  state.extrinsic.q, state.extrinsic.t, p_map, &uv)) {
    return false;
  }
  const double m = margin_px;
  return uv.x() > -m && uv.y() > -m && uv.x() < camera.intrinsics().width + m &&
         uv.y() < camera.intrinsics().height + m;
}

void AddPosePriors(const WindowSnapshot& snapshot, const BackendOptions& options,
                   WindowState* state, ceres::Problem* problem) {
  for (std::size_t i = 0; i < state->frames.size(); ++i) {
    PoseBlocks& pose = state->frames[i];
    if (!problem->HasParameterBlock(pose.q)) continue;
    problem->SetManifold(pose.q, new ceres::EigenQuaternionManifold);
    if (!snapshot.frames[i].in_window) {
      problem->SetParameterBlockConstant(pose.q);
      problem->SetParameterBlockConstant(pose.t);
      continue;
    }
    problem->AddResidualBlock(
        residuals::PosePriorResidual::Create(snapshot.frames[i].T_map_base_odom,
                                             options.pose_prior_sigma_trans_m,
                                             options.pose_prior_sigma_rot_rad),
        nullptr, pose.q, pose.t);
  }
}

void AddMotionPriors(const WindowSnapshot& snapshot, const BackendOptions& options,
                     MotionPriorTriples triples, WindowState* state, ceres::Problem* problem) {
  if (!options.motion_prior) return;
  for (std::size_t i = 1; i + 1 < state->frames.size(); ++i) {
    const WindowFrame& a = snapshot.frames[i - 1];
    const WindowFrame& b = snapshot.frames[i];
    const WindowFrame& c = snapshot.frames[i + 1];
    if (b.index != a.index + 1 || c.index != b.index + 1) continue;
    PoseBlocks &pa = state->frames[i - 1], &pb = state->frames[i], &pc = state->frames[i + 1];
    if (!problem->HasParameterBlock(pb.q)) continue;  // no data on the middle one
    if (triples == MotionPriorTriples::kAllInProblem &&
        (!b.in_window || !problem->HasParameterBlock(pa.q) || !problem->HasParameterBlock(pc.q))) {
      continue;
    }
    const double dt_a = b.stamp - a.stamp, dt_b = c.stamp - b.stamp;
    if (!(dt_a > 0.0) || !(dt_b > 0.0)) continue;
    problem->AddResidualBlock(
        residuals::MotionPriorResidual::Create(dt_a, dt_b, options.motion_sigma_acc_mps2,
                                               options.motion_sigma_angular_acc_radps2),
        nullptr, pa.q, pa.t, pb.q, pb.t, pc.q, pc.t);
  }
}

ceres::LossFunction* MakeLoss(const BackendOptions& options) {
  switch (options.robust_kernel) {
    case RobustKernel::kHuber:
      return new ceres::HuberLoss(options.robust_scale);
    case RobustKernel::kCauchy:
      return new ceres::CauchyLoss(options.robust_scale);
    case RobustKernel::kNone:
      return nullptr;
  }
  return nullptr;
}

ceres::Solver::Summary Solve(const BackendOptions& options, double time_limit_s,
                             ceres::Problem* problem) {
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  solver.max_num_iterations = options.max_iterations;
  if (std::isfinite(time_limit_s)) solver.max_solver_time_in_seconds = std::max(0.0, time_limit_s);
  solver.num_threads = 1;
  solver.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  if (problem->NumResidualBlocks() > 0) ceres::Solve(solver, problem, &summary);
  return summary;
}

}  // namespace window_solve
}  // namespace ipm_road_mapper
