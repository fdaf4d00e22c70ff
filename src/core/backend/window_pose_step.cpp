#include "ipm_road_mapper/core/backend/window_pose_step.h"

#include "ipm_road_mapper/core/backend/residuals/corner_reprojection_residual.h"
#include "ipm_road_mapper/core/backend/residuals/edge_reprojection_residual.h"
#include "ipm_road_mapper/core/backend/residuals/ppsr_residual.h"

namespace ipm_road_mapper {
namespace window_solve {
namespace {

// After a pose step: which window frames it moved, and the covariance of the newest of them
// (what the mapper carries forward to the frames that follow it).
void RecordPoseStep(const WindowSnapshot& snapshot, ceres::Problem* problem, WindowState* state) {
  state->covariance_slot = -1;
  for (std::size_t i = 0; i < state->frames.size(); ++i) {
    const PoseBlocks& pose = state->frames[i];
    if (!snapshot.frames[i].in_window || !problem->HasParameterBlock(pose.q)) continue;
    state->optimized[i] = true;
    state->covariance_slot = static_cast<int>(i);  // frames are sorted by index
  }
  if (state->covariance_slot < 0 || !snapshot.newest_pose_covariance) return;
  const PoseBlocks& newest = state->frames[state->covariance_slot];
  if (!ComputePoseCovariance(problem, newest.q, newest.t, &state->covariance)) {
    state->covariance_slot = -1;
  }
}

}  // namespace

ceres::Solver::Summary PoseStep(const WindowSnapshot& snapshot, const BackendOptions& options,
                                WindowState* state, int* blocks) {
  ceres::Problem problem;
  ceres::LossFunction* loss = MakeLoss(options);
  const PinholeCamera camera(snapshot.camera);
  const double* q_bc = state->extrinsic.q;
  const double* t_bc = state->extrinsic.t;
  *blocks = 0;
  for (const CornerMeasurement& m : state->corner_measurements) {
    if (!snapshot.markings[m.marking].mature || !snapshot.frames[m.slot].in_window) continue;
    PoseBlocks& pose = state->frames[m.slot];
    problem.AddResidualBlock(
        residuals::CornerReprojectionPoseStepResidual::Create(
            camera, m.uv, options.pixel_sigma_px, state->corners[m.marking][m.corner], q_bc, t_bc),
        loss, pose.q, pose.t);
    ++*blocks;
  }
  for (const EdgeMeasurement& m : state->edge_measurements) {
    if (!snapshot.markings[m.marking].mature || !snapshot.frames[m.slot].in_window) continue;
    PoseBlocks& pose = state->frames[m.slot];
    const auto& corners = state->corners[m.marking];
    problem.AddResidualBlock(residuals::EdgeReprojectionPoseStepResidual::Create(
                                 camera, m.uv, options.pixel_sigma_px, corners[m.side],
                                 corners[(m.side + 1) % 4], q_bc, t_bc),
                             loss, pose.q, pose.t);
    ++*blocks;
  }
  if (options.lane_residual == LaneResidual::kPpsr) {
    for (const LanePixel& px : state->lane_pixels) {
      if (!snapshot.frames[px.slot].in_window) continue;  // a context frame's pose is data
      const auto& cps = state->control_points[px.lane];
      PoseBlocks& pose = state->frames[px.slot];
      problem.AddResidualBlock(residuals::PpsrPoseStepResidual::Create(
                                   camera, px.uv, options.pixel_sigma_px, cps[px.segment + 1],
                                   cps[px.segment + 2], q_bc, t_bc),
                               loss, pose.q, pose.t);
      ++*blocks;
    }
  }
  if (*blocks == 0) {
    delete loss;
    return ceres::Solver::Summary();
  }
  // The motion prior over consecutive frames (by index) that touch a free pose; the others
  // of a triple join as data. Then every pose's odometry prior (context frames: data).
  AddMotionPriors(snapshot, options, MotionPriorTriples::kMiddleInProblem, state, &problem);
  AddPosePriors(snapshot, options, state, &problem);
  const ceres::Solver::Summary summary = Solve(options, state->step_time_limit_s, &problem);
  if (summary.IsSolutionUsable()) RecordPoseStep(snapshot, &problem, state);
  return summary;
}

}  // namespace window_solve
}  // namespace ipm_road_mapper
