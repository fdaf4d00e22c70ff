// Internal to SolveWindow: the measurements a window solve uses, collected from the
// snapshot with the build-time checks (docs/backend.md, "One solve").
#pragma once

#include "ipm_road_mapper/core/backend/window_state.h"

namespace ipm_road_mapper {
namespace window_solve {

// Collects the corner measurements of the window's frames, each re-measured from its
// outline on the road plane at the marking (road_surface.h, from the window's frames; see
// marking_measurement.h; the flat-ground corners are the fallback).
void CollectCornerMeasurements(const WindowSnapshot& snapshot, const BackendOptions& options,
                               WindowState* state);

// Assigns each selected lane pixel of the window to the spline segment its IPM point falls
// on (at most max_lane_points_per_observation per observation, spread over its points).
void CollectLanePixels(const WindowSnapshot& snapshot, const BackendOptions& options,
                       WindowState* state);

// PSR (the ablation) only: each lane pixel's IPM point again, from the state's current poses
// and extrinsic, and its closest point on the state's current spline. The 3D point is what
// PSR measures, so it follows the extrinsic the solve refines (PPSR's pixels see it
// directly); without this, lanes kept the extrinsic their window began with.
void RefreshPsrPoints(const WindowSnapshot& snapshot, const BackendOptions& options,
                      WindowState* state);

}  // namespace window_solve
}  // namespace ipm_road_mapper
