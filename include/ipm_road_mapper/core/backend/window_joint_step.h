// Internal to SolveWindow: the joint step of the final global solve, map, extrinsic and poses
// free in one problem (docs/backend.md, "End of input: one global solve").
#pragma once

#include <ceres/ceres.h>

#include <optional>

#include "ipm_road_mapper/core/backend/window_state.h"

namespace ipm_road_mapper {
namespace window_solve {

// One Levenberg-Marquardt solve over the map points, the extrinsic and the window's poses
// together: every measurement of a mature marking and every lane pixel with its frame's pose
// free (pixel sigma alone: the pose's uncertainty is a variable here, not noise), the other
// markings' measurements with the pose as data (the map step's whitening; partial-only
// markings see a held copy of the extrinsic, as there), the map points' priors, the extrinsic
// prior, and the pose and motion priors of the pose step. The extrinsic's lever arm (x, y) is
// held: with the poses free a shift of the camera and of every pose explains the data alike.
// Why: the alternation of the two steps moves along the valley where camera and vehicle motion
// trade against each other by a few thousandths of a degree per round (public_road: 0.004 ->
// 0.0013 deg per round over 12 rounds, not converged); the joint step goes down it at once.
// Observability-aware (extrinsic_observability.h, Schneider et al. RA-L 2019): the joint
// problem's own information on the extrinsic (every residual but the extrinsic prior, the map
// points and poses marginalized at the values before the step), with the lever arm held, is
// compared with the mounting prior; each direction it does not observe
// (extrinsic_min_information_ratio) is held at the extrinsic before the step, and only the
// observed ones move. `observability` (optional) receives that analysis when the extrinsic
// is free in the step.
ceres::Solver::Summary JointStep(const WindowSnapshot& snapshot, const BackendOptions& options,
                                 WindowState* state, int* blocks,
                                 std::optional<ExtrinsicObservability>* observability = nullptr);

// The analysis of the joint step's information (chart, extrinsic_observability.h) with the
// lever arm (x, y) held: its rows and columns dropped, so x and y come out unobserved and
// every other direction is judged by what the data says with the lever arm known.
ExtrinsicObservability JointObservability(const Matrix6d& information,
                                          const BackendOptions& options);

}  // namespace window_solve
}  // namespace ipm_road_mapper
