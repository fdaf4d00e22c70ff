// Internal to SolveWindow: what a window's data observes of the extrinsic
// (extrinsic_observability.h), the guard that refuses a refined extrinsic the held-out
// frames do not prefer, and the calibration (covariance, observed axes) of the result.
#pragma once

#include "ipm_road_mapper/core/backend/window_state.h"

namespace ipm_road_mapper {
namespace window_solve {

// What the solve's data observes of the extrinsic (extrinsic_observability.h), at the
// state's start: the information of its map-step measurements (the held-out ones excluded)
// with the map points and the window's poses marginalized, each pose on its odometry and
// under the motion prior as in the pose step (context frames are data). Marginalizing the
// poses matters: the map step takes them as data, and a direction of the extrinsic that a
// pose error explains as well (the camera's yaw against the heading, with noisy odometry)
// is not observed.
void ObserveExtrinsic(const WindowSnapshot& snapshot, const BackendOptions& options,
                      WindowState* state);

// The guard against harm, after the first map step (the poses still the snapshot's): the
// refined extrinsic is kept unless it explains the held-out frames' measurements worse
// than the starting one (beyond their noise), each with the map re-fit to the training
// frames. Otherwise the state becomes the reference fit and the extrinsic stays held for
// the rest of the solve. Nothing is judged when no direction was updated.
void JudgeExtrinsic(const WindowSnapshot& snapshot, const BackendOptions& options,
                    double time_limit_s, WindowState* state, WindowState* reference,
                    WindowResult* result);

// The extrinsic's calibration after the solve: which directions its data observed and the
// covariance of the prior plus that observed information.
void FillCalibration(const WindowSnapshot& snapshot, const WindowState& state,
                     WindowResult* result);

}  // namespace window_solve
}  // namespace ipm_road_mapper
