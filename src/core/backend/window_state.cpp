#include "ipm_road_mapper/core/backend/window_state.h"

#include <algorithm>
#include <cmath>

#include "ipm_road_mapper/core/backend/residuals/corner_reprojection_residual.h"

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
