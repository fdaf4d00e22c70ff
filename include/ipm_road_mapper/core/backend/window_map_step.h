// Internal to SolveWindow: the map + extrinsic step (marking corners, lane control points and
// the extrinsic free, the window's poses data) and the pieces the extrinsic's observability
// and guard share with it.
#pragma once

#include <vector>

#include "ipm_road_mapper/core/backend/window_state.h"

namespace ipm_road_mapper {
namespace window_solve {

// The priors of the free map points (what makes them well posed besides the measurements):
// on the road surface (softly), z optionally held; control points anchored along their lane
// (PPSR leaves that direction free: a gauge of each point) and smooth.
void AddMapPointPriors(const BackendOptions& options, WindowState* state,
                       ceres::Problem* problem_ptr);

// The extrinsic's blocks, when the problem has them: the prior of the retired data and the
// mounting (counted there once), the rotation on the quaternion manifold, both held when the
// extrinsic is not optimized or frozen. Returns whether it is free (the caller then holds
// what its step cannot observe).
bool AddExtrinsicPrior(const WindowSnapshot& snapshot, const BackendOptions& options,
                       WindowState* state, ceres::Problem* problem);

// Weight of the hold on an unobserved direction, in whitened units (times the mounting
// prior's information): the direction stays within 1 % of a prior sigma of its start value.
constexpr double kUnobservedHoldWeight = 1e4;

// The observability-aware update (extrinsic_observability.h): every direction that
// `observability` does not observe is held at T_base_cam_start (a stiff ExtrinsicPriorResidual
// on the state's extrinsic); the observed ones move. The map step holds what its solve's data
// does not observe at the solve's start (extrinsic_hold_unobserved), the joint step what the
// joint problem does not observe at the extrinsic before it.
void HoldUnobservedDirections(const ExtrinsicObservability& observability,
                              const Eigen::Isometry3d& T_base_cam_start, WindowState* state,
                              ceres::Problem* problem);

// Which of a state's measurements a problem gets.
enum class Measurements { kTraining, kHeldOut, kAll };

// Adds the corner and lane-pixel residuals of the map step (pixel sigma and pose uncertainty,
// pose_uncertainty.h; poses as data) for the chosen measurements; returns how many.
int AddMapStepMeasurements(const WindowSnapshot& snapshot, const BackendOptions& options,
                           Measurements which, ceres::LossFunction* loss, WindowState* state,
                           ceres::Problem* problem);

// The map + extrinsic step: marking corners, lane control points and the extrinsic free,
// the window's poses data (which also fixes the gauge: the map hangs on the poses).
ceres::Solver::Summary MapStep(const WindowSnapshot& snapshot, const BackendOptions& options,
                               WindowState* state, int* blocks);

// The total robustified cost of the held-out measurements at the state's map, extrinsic and
// poses: the evidence the guard judges an extrinsic by.
// (Per held-out measurement, in the order they were added: the same order for any state of
// one snapshot.)
std::vector<double> HeldOutCosts(const WindowSnapshot& snapshot, const BackendOptions& options,
                                 WindowState* state);

}  // namespace window_solve
}  // namespace ipm_road_mapper
