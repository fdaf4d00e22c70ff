#include "ipm_road_mapper/core/backend/window_problem.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <chrono>
#include <optional>

#include "ipm_road_mapper/core/backend/window_extrinsic.h"
#include "ipm_road_mapper/core/backend/window_extrinsic_validation.h"
#include "ipm_road_mapper/core/backend/window_joint_step.h"
#include "ipm_road_mapper/core/backend/window_map_step.h"
#include "ipm_road_mapper/core/backend/window_measurements.h"
#include "ipm_road_mapper/core/backend/window_pose_step.h"
#include "ipm_road_mapper/core/backend/window_state.h"
#include "ipm_road_mapper/core/geometry/rigid_transform.h"

namespace ipm_road_mapper {

using namespace window_solve;  // NOLINT: the steps of this one solve

WindowResult SolveWindow(const WindowSnapshot& snapshot, const BackendOptions& options,
                         double time_budget_s) {
  const auto start = std::chrono::steady_clock::now();
  auto remaining_s = [&] {
    return time_budget_s -
           std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  WindowResult result;
  result.sequence = snapshot.sequence;
  WindowState state(snapshot);
  CollectCornerMeasurements(snapshot, options, &state);
  if (options.lane_residual != LaneResidual::kNone) CollectLanePixels(snapshot, options, &state);

  // Map + extrinsic step, then the pose step, `rounds` times.
  bool usable = true;
  auto run = [&](bool map_step) {
    state.step_time_limit_s = remaining_s();
    if (!(state.step_time_limit_s > 0.0)) return;  // out of time: the steps so far stand
    int blocks = 0;
    const ceres::Solver::Summary summary = map_step ? MapStep(snapshot, options, &state, &blocks)
                                                    : PoseStep(snapshot, options, &state, &blocks);
    if (blocks == 0) return;
    result.residual_blocks = std::max(result.residual_blocks, blocks);
    usable = summary.IsSolutionUsable();
    result.iterations += static_cast<int>(summary.iterations.size());
    if (result.initial_cost == 0.0) result.initial_cost = summary.initial_cost;
    result.final_cost = summary.final_cost;
    if (map_step || !usable) result.summary = summary.BriefReport();
  };
  // The guard: the first map step leaves every N-th frame out; a reference fit of the map
  // with the extrinsic held at its start value is made from the same start.
  const bool guard = options.optimize_extrinsic && options.extrinsic_holdout_every_n_frames > 0;
  std::optional<WindowState> reference;
  if (guard) {
    const std::size_t n = static_cast<std::size_t>(options.extrinsic_holdout_every_n_frames);
    for (std::size_t i = 0; i < snapshot.frames.size(); ++i) {
      state.held_out[i] = snapshot.frames[i].index % n == n - 1;
    }
    state.hold_out = true;
    reference = state;
    reference->extrinsic_frozen = true;
  }
  if (options.optimize_extrinsic) ObserveExtrinsic(snapshot, options, &state);
  for (int round = 0; round < options.rounds && usable; ++round) {
    run(true);
    if (round == 0 && guard && usable) {
      JudgeExtrinsic(snapshot, options, remaining_s(), &state, &*reference, &result);
      reference.reset();
    }
    if (usable && options.pose_update) run(false);
  }
  // The joint step (final global solve): down the valley the alternation crawls along. Its
  // lanes are PPSR pixels, or PSR points carried by their frames' poses, with the poses
  // free. Without a lane residual the lanes follow the poses at export anyway.
  if (snapshot.joint_step_iterations > 0 && usable) {
    state.step_time_limit_s = remaining_s();
    if (state.step_time_limit_s > 0.0) {
      BackendOptions joint = options;
      joint.max_iterations = snapshot.joint_step_iterations;
      int blocks = 0;
      std::optional<ExtrinsicObservability> observed;
      const ceres::Solver::Summary summary = JointStep(snapshot, joint, &state, &blocks, &observed);
      // Of the four directions free in it (the lever arm x, y is held), those not observed.
      if (observed) result.joint_extrinsic_held = std::max(0, 4 - observed->rank);
      if (blocks > 0) {
        usable = summary.IsSolutionUsable();
        result.iterations += static_cast<int>(summary.iterations.size());
        result.final_cost = summary.final_cost;
        result.summary = summary.BriefReport();
      }
    }
  }
  // A refined extrinsic of the drive is used only once cross-validated. Halves that run out
  // of time stop at (or near) the solved state they start from and agree with it by
  // construction, so a validation begun or ended past the budget proves nothing: the result
  // is not usable, and what the windows made stands.
  bool validation_timed_out = false;
  if (snapshot.cross_validate_extrinsic && options.optimize_extrinsic && usable) {
    if (remaining_s() > 0.0) {
      result.extrinsic_directions_reverted =
          CrossValidateExtrinsic(snapshot, options, remaining_s(), &state);
    }
    validation_timed_out = !(remaining_s() > 0.0);
    usable = !validation_timed_out;
  }
  FillCalibration(snapshot, state, &result);

  result.T_base_cam = state.extrinsic.ToIsometry();
  result.extrinsic_change_rad = RotationAngleBetween(result.T_base_cam, snapshot.T_base_cam);
  result.extrinsic_change_m =
      (result.T_base_cam.translation() - snapshot.T_base_cam.translation()).norm();
  if (validation_timed_out) {
    result.reason = "out of time: the refined extrinsic was not cross-validated";
  } else if (!usable) {
    result.reason = "solver: " + result.summary;
  } else if (result.extrinsic_change_rad > options.max_extrinsic_change_rad ||
             result.extrinsic_change_m > options.max_extrinsic_change_m) {
    usable = false;
    result.reason = "extrinsic change beyond the trust bound";
  }
  result.usable = usable;

  for (std::size_t i = 0; i < snapshot.frames.size(); ++i) {
    WindowFrame frame = snapshot.frames[i];
    frame.T_map_base = state.frames[i].ToIsometry();
    frame.optimized = state.optimized[i];
    result.frames.push_back(frame);
  }
  if (state.covariance_slot >= 0) {
    result.covariance_frame =
        static_cast<std::int64_t>(snapshot.frames[state.covariance_slot].index);
    result.T_map_base_covariance = state.covariance;
  }
  for (std::size_t m = 0; m < snapshot.markings.size(); ++m) {
    result.markings.push_back({snapshot.markings[m].id, state.corners[m], {}});
  }
  for (std::size_t l = 0; l < snapshot.lanes.size(); ++l) {
    std::vector<Eigen::Vector3d> cps = state.control_points[l];
    if (options.lane_residual == LaneResidual::kPpsr && cps.size() >= 4) {
      // Phantom ends follow the optimized interior (PPSR never touches them).
      cps.front() = 2.0 * cps[1] - cps[2];
      cps.back() = 2.0 * cps[cps.size() - 2] - cps[cps.size() - 3];
    }
    result.lanes.push_back({snapshot.lanes[l].id, snapshot.lanes[l].first_cp_index, cps, {}});
  }
  result.solve_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace ipm_road_mapper
