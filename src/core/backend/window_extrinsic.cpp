#include "ipm_road_mapper/core/backend/window_extrinsic.h"

#include <cmath>
#include <vector>

#include "ipm_road_mapper/core/backend/residuals/corner_reprojection_residual.h"
#include "ipm_road_mapper/core/backend/residuals/ppsr_residual.h"
#include "ipm_road_mapper/core/backend/window_map_step.h"

namespace ipm_road_mapper {
namespace window_solve {

void ObserveExtrinsic(const WindowSnapshot& snapshot, const BackendOptions& options,
                      WindowState* state) {
  ceres::Problem problem;
  ceres::LossFunction* loss = MakeLoss(options);
  const PinholeCamera camera(snapshot.camera);
  double* q_bc = state->extrinsic.q;
  double* t_bc = state->extrinsic.t;
  int blocks = 0;
  auto wanted = [&](std::size_t slot) { return !(state->hold_out && state->held_out[slot]); };
  if (options.optimize_markings) {
    for (const CornerMeasurement& m : state->corner_measurements) {
      if (!wanted(m.slot) || snapshot.markings[m.marking].partial_only) continue;
      PoseBlocks& pose = state->frames[m.slot];
      problem.AddResidualBlock(
          residuals::CornerReprojectionResidual::Create(camera, m.uv, options.pixel_sigma_px), loss,
          state->corners[m.marking][m.corner].data(), pose.q, pose.t, q_bc, t_bc);
      ++blocks;
    }
  }
  if (options.lane_residual == LaneResidual::kPpsr) {
    for (const LanePixel& px : state->lane_pixels) {
      if (!wanted(px.slot)) continue;
      auto& cps = state->control_points[px.lane];
      PoseBlocks& pose = state->frames[px.slot];
      problem.AddResidualBlock(
          residuals::PpsrResidual::Create(camera, px.uv, options.pixel_sigma_px), loss,
          cps[px.segment + 1].data(), cps[px.segment + 2].data(), pose.q, pose.t, q_bc, t_bc);
      ++blocks;
    }
  }
  if (blocks == 0) {
    delete loss;
    return;
  }
  AddMapPointPriors(options, state, &problem);
  // The window's poses marginalized as in the pose step: on their odometry priors and under
  // the motion prior (context frames are data).
  AddPosePriors(snapshot, options, state, &problem);
  AddMotionPriors(snapshot, options, MotionPriorTriples::kAllInProblem, state, &problem);
  problem.SetManifold(q_bc, new ceres::EigenQuaternionManifold);
  state->observability = AnalyzeObservability(
      ExtrinsicInformation(&problem, q_bc, t_bc, {}),
      PriorSigma(options.rotation_prior_sigma_rad, options.translation_prior_sigma_m),
      options.extrinsic_min_information_ratio);
  state->observability_valid = true;
}

void JudgeExtrinsic(const WindowSnapshot& snapshot, const BackendOptions& options,
                    double time_limit_s, WindowState* state, WindowState* reference,
                    WindowResult* result) {
  state->hold_out = false;  // the later steps use every measurement
  if (!state->observability_valid || state->observability.rank == 0) return;
  const std::vector<double> candidate = HeldOutCosts(snapshot, options, state);
  reference->step_time_limit_s = time_limit_s;
  int blocks = 0;
  MapStep(snapshot, options, reference, &blocks);
  const std::vector<double> held = HeldOutCosts(snapshot, options, reference);
  if (candidate.size() != held.size()) return;  // cannot happen: one snapshot, one order
  // The difference of the costs and its spread over the measurements: worse beyond
  // extrinsic_holdout_sigmas of that spread (an update that changes little moves the costs
  // both ways by chance, and must not be refused by a coin flip) keeps the start.
  double difference = 0.0, spread = 0.0;
  for (std::size_t i = 0; i < held.size(); ++i) {
    const double d = candidate[i] - held[i];
    result->holdout_cost_candidate += candidate[i];
    result->holdout_cost_reference += held[i];
    difference += d;
    spread += d * d;
  }
  result->holdout_blocks = static_cast<int>(held.size());
  if (difference <= options.extrinsic_holdout_sigmas * std::sqrt(spread)) return;
  result->extrinsic_rejected = true;
  *state = std::move(*reference);
  state->hold_out = false;
  state->extrinsic_frozen = true;
}

void FillCalibration(const WindowSnapshot& snapshot, const WindowState& state,
                     WindowResult* result) {
  Matrix6d information = snapshot.extrinsic_prior.H();
  if (state.observability_valid && !state.extrinsic_frozen) {
    information += state.observability.ObservedInformation();
    result->extrinsic_observed = state.observability.axis_observed;
    result->extrinsic_observed_rank = state.observability.rank;
  }
  result->T_base_cam_covariance = information.inverse();
}

}  // namespace window_solve
}  // namespace ipm_road_mapper
