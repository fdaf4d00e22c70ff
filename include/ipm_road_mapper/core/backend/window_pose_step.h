// Internal to SolveWindow: the pose-update step (the window's poses free with their odometry
// priors and the motion prior; map and extrinsic data, which fix the gauge).
#pragma once

#include "ipm_road_mapper/core/backend/window_state.h"

namespace ipm_road_mapper {
namespace window_solve {

// The pose-update step: the window's poses free with their odometry priors; map and
// extrinsic data (the gauge is fixed by the map). Records which frames it moved and the
// covariance of the newest of them.
ceres::Solver::Summary PoseStep(const WindowSnapshot& snapshot, const BackendOptions& options,
                                WindowState* state, int* blocks);

}  // namespace window_solve
}  // namespace ipm_road_mapper
