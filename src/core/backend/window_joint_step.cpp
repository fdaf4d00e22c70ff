#include "ipm_road_mapper/core/backend/window_joint_step.h"

#include "ipm_road_mapper/core/backend/residuals/corner_reprojection_residual.h"
#include "ipm_road_mapper/core/backend/residuals/edge_reprojection_residual.h"
#include "ipm_road_mapper/core/backend/residuals/pose_uncertainty.h"
#include "ipm_road_mapper/core/backend/residuals/ppsr_residual.h"
#include "ipm_road_mapper/core/backend/residuals/psr_residual.h"
#include "ipm_road_mapper/core/backend/window_map_step.h"
#include "ipm_road_mapper/core/backend/window_measurements.h"

namespace ipm_road_mapper {
namespace window_solve {

namespace {

// The joint problem's residual blocks that are the extrinsic prior (AddExtrinsicPrior): the
// only ones on the extrinsic's two blocks alone (a hold added later would be too).
std::vector<ceres::ResidualBlockId> ExtrinsicPriorBlocks(ceres::Problem* problem, double* q_bc,
                                                         double* t_bc) {
  std::vector<ceres::ResidualBlockId> on_q, prior;
  problem->GetResidualBlocksForParameterBlock(q_bc, &on_q);
  for (ceres::ResidualBlockId id : on_q) {
    std::vector<double*> blocks;
    problem->GetParameterBlocksForResidualBlock(id, &blocks);
    if (blocks.size() == 2 && blocks[0] == q_bc && blocks[1] == t_bc) prior.push_back(id);
  }
  return prior;
}

}  // namespace

ExtrinsicObservability JointObservability(const Matrix6d& information,
                                          const BackendOptions& options) {
  Matrix6d held_lever_arm = information;
  held_lever_arm.row(3).setZero();
  held_lever_arm.row(4).setZero();
  held_lever_arm.col(3).setZero();
  held_lever_arm.col(4).setZero();
  return AnalyzeObservability(
      held_lever_arm,
      PriorSigma(options.rotation_prior_sigma_rad, options.translation_prior_sigma_m),
      options.extrinsic_min_information_ratio);
}

ceres::Solver::Summary JointStep(const WindowSnapshot& snapshot, const BackendOptions& options,
                                 WindowState* state, int* blocks,
                                 std::optional<ExtrinsicObservability>* observability) {
  ceres::Problem problem;
  ceres::LossFunction* loss = MakeLoss(options);
  const PinholeCamera camera(snapshot.camera);
  double* q_bc = state->extrinsic.q;
  double* t_bc = state->extrinsic.t;
  const double sigma_px = options.pixel_sigma_px;
  *blocks = 0;
  // A measurement's pose is free when its frame is in the window and, for a marking, when the
  // marking is mature (as in the pose step: a new marking sits where flat IPM put it).
  auto pose_free = [&](std::size_t slot) { return snapshot.frames[slot].in_window; };
  const Eigen::Isometry3d T_base_cam = state->extrinsic.ToIsometry();
  const Eigen::Vector3d sigma_t =
      options.map_step_pose_sigma_scale * options.pose_prior_sigma_trans_m;
  const Eigen::Vector3d sigma_r =
      options.map_step_pose_sigma_scale * options.pose_prior_sigma_rot_rad;
  state->held_extrinsic = state->extrinsic;
  bool held_used = false;
  if (options.optimize_markings) {
    for (const CornerMeasurement& m : state->corner_measurements) {
      const WindowMarking& marking = snapshot.markings[m.marking];
      PoseBlocks& pose = state->frames[m.slot];
      auto& corner = state->corners[m.marking][m.corner];
      if (marking.mature && !marking.partial_only && pose_free(m.slot)) {
        problem.AddResidualBlock(
            residuals::CornerReprojectionResidual::Create(camera, m.uv, sigma_px), loss,
            corner.data(), pose.q, pose.t, q_bc, t_bc);
      } else {
        const bool held = marking.partial_only;
        held_used = held_used || held;
        problem.AddResidualBlock(
            residuals::CornerReprojectionMapStepResidual::Create(
                camera, m.uv,
                residuals::PoseUncertaintyWhitening(camera, state->poses[m.slot], T_base_cam,
                                                    corner, sigma_px, sigma_t, sigma_r),
                pose.q, pose.t),
            loss, corner.data(), held ? state->held_extrinsic.q : q_bc,
            held ? state->held_extrinsic.t : t_bc);
      }
      ++*blocks;
    }
    for (const EdgeMeasurement& m : state->edge_measurements) {
      const WindowMarking& marking = snapshot.markings[m.marking];
      PoseBlocks& pose = state->frames[m.slot];
      auto& corners = state->corners[m.marking];
      double* c1 = corners[m.side].data();
      double* c2 = corners[(m.side + 1) % 4].data();
      if (marking.mature && !marking.partial_only && pose_free(m.slot)) {
        problem.AddResidualBlock(
            residuals::EdgeReprojectionResidual::Create(camera, m.uv, sigma_px), loss, c1, c2,
            pose.q, pose.t, q_bc, t_bc);
      } else {
        const bool held = marking.partial_only;
        held_used = held_used || held;
        problem.AddResidualBlock(residuals::EdgeReprojectionMapStepResidual::Create(
                                     camera, m.uv, sigma_px, pose.q, pose.t),
                                 loss, c1, c2, held ? state->held_extrinsic.q : q_bc,
                                 held ? state->held_extrinsic.t : t_bc);
      }
      ++*blocks;
    }
  }
  if (held_used) {
    problem.SetManifold(state->held_extrinsic.q, new ceres::EigenQuaternionManifold);
    problem.SetParameterBlockConstant(state->held_extrinsic.q);
    problem.SetParameterBlockConstant(state->held_extrinsic.t);
  }
  if (options.lane_residual == LaneResidual::kPpsr) {
    for (const LanePixel& px : state->lane_pixels) {
      auto& cps = state->control_points[px.lane];
      PoseBlocks& pose = state->frames[px.slot];
      problem.AddResidualBlock(residuals::PpsrResidual::Create(camera, px.uv, sigma_px), loss,
                               cps[px.segment + 1].data(), cps[px.segment + 2].data(), pose.q,
                               pose.t, q_bc, t_bc);
      ++*blocks;
    }
  } else if (options.lane_residual == LaneResidual::kPsr) {
    RefreshPsrPoints(snapshot, options, state);
    for (const LanePixel& px : state->lane_pixels) {
      auto& cps = state->control_points[px.lane];
      PoseBlocks& pose = state->frames[px.slot];
      problem.AddResidualBlock(
          residuals::PsrJointResidual::Create(px.p_base, px.u, options.psr_sigma_m), loss,
          cps[px.segment].data(), cps[px.segment + 1].data(), cps[px.segment + 2].data(),
          cps[px.segment + 3].data(), pose.q, pose.t);
      ++*blocks;
    }
  }
  if (*blocks == 0) {
    delete loss;
    return ceres::Solver::Summary();
  }
  AddMapPointPriors(options, state, &problem);
  const bool extrinsic_free = AddExtrinsicPrior(snapshot, options, state, &problem);
  AddMotionPriors(snapshot, options, MotionPriorTriples::kMiddleInProblem, state, &problem);
  AddPosePriors(snapshot, options, state, &problem);
  if (!options.pose_update) {
    for (PoseBlocks& pose : state->frames) {
      if (!problem.HasParameterBlock(pose.q)) continue;
      problem.SetParameterBlockConstant(pose.q);
      problem.SetParameterBlockConstant(pose.t);
    }
  }
  if (extrinsic_free) {
    // What this problem's data (everything but the extrinsic prior) observes of the
    // extrinsic, the map and the poses marginalized, with the lever arm held; the directions
    // it does not observe stay where the alternation left them.
    const ExtrinsicObservability joint = JointObservability(
        ExtrinsicInformation(&problem, q_bc, t_bc, ExtrinsicPriorBlocks(&problem, q_bc, t_bc)),
        options);
    HoldUnobservedDirections(joint, T_base_cam, state, &problem);
    if (observability != nullptr) *observability = joint;
    // The lever arm x, y: with the poses free, a shift of the camera and of every pose
    // explains the data alike (docs/backend.md, "What is observable"); free here it moved
    // 6-12 cm the wrong way on curvy and port seeds 2-3 (and the halves then agreed).
    problem.SetManifold(t_bc, new ceres::SubsetManifold(3, {0, 1}));
  }
  return Solve(options, state->step_time_limit_s, &problem);
}

}  // namespace window_solve
}  // namespace ipm_road_mapper
