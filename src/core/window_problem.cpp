#include "ipm_road_mapper/core/window_problem.h"

#include <ceres/ceres.h>

#include <chrono>
#include <map>
#include <memory>

#include "ipm_road_mapper/core/catmull_rom_spline.h"
#include "ipm_road_mapper/core/ipm.h"
#include "ipm_road_mapper/core/rigid_transform.h"
#include "ipm_road_mapper/core/residuals/corner_reprojection_residual.h"
#include "ipm_road_mapper/core/residuals/ground_height_prior_residual.h"
#include "ipm_road_mapper/core/residuals/point_anchor_residual.h"
#include "ipm_road_mapper/core/residuals/pose_prior_residual.h"
#include "ipm_road_mapper/core/residuals/ppsr_residual.h"
#include "ipm_road_mapper/core/residuals/psr_residual.h"
#include "ipm_road_mapper/core/residuals/rotation_prior_residual.h"
#include "ipm_road_mapper/core/residuals/translation_prior_residual.h"

namespace ipm_road_mapper {
namespace {

// Sigma of the along-lane anchor of each control point (see point_anchor_residual.h).
constexpr double kControlPointAnchorSigmaM = 1.0;
// Lane pixels whose IPM point is farther than this from the spline are not used.
constexpr double kMaxLanePixelDistanceM = 1.5;

// A rigid transform as Ceres parameter blocks: quaternion (x, y, z, w) and translation.
struct PoseBlocks {
  double q[4];
  double t[3];
  explicit PoseBlocks(const Eigen::Isometry3d& T) {
    Eigen::Map<Eigen::Quaterniond> q_map(q);
    q_map = Eigen::Quaterniond(T.linear()).normalized();
    Eigen::Map<Eigen::Vector3d> t_map(t);
    t_map = T.translation();
  }
  Eigen::Isometry3d ToIsometry() const {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::Map<const Eigen::Quaterniond>(q).normalized().toRotationMatrix();
    T.translation() = Eigen::Map<const Eigen::Vector3d>(t);
    return T;
  }
};

// One lane pixel's residual: which lane, frame and control points (global c0 index of the
// segment, i.e. the segment's control points are c[i] .. c[i + 3]).
struct LanePixel {
  std::size_t lane = 0;
  std::size_t frame_slot = 0;
  Eigen::Vector2d uv;
  int segment = 0;
  double u = 0.0;
  Eigen::Vector3d q_map;  // IPM point at build time (PSR)
};

// The mutable state of one solve, initialized from the snapshot.
struct WindowState {
  PoseBlocks extrinsic;
  std::vector<PoseBlocks> frames;
  std::map<std::size_t, std::size_t> slot_of_frame;
  std::vector<std::array<Eigen::Vector3d, 4>> corners;
  std::vector<std::vector<Eigen::Vector3d>> control_points;
  std::vector<LanePixel> lane_pixels;
  explicit WindowState(const WindowSnapshot& s) : extrinsic(s.T_base_cam) {
    for (std::size_t i = 0; i < s.frames.size(); ++i) {
      frames.emplace_back(s.frames[i].T_map_base);
      slot_of_frame[s.frames[i].index] = i;
    }
    for (const WindowMarking& m : s.markings) corners.push_back(m.corners_map);
    for (const WindowLane& l : s.lanes) control_points.push_back(l.control_points_map);
  }
};

// Assigns each used lane pixel to the spline segment its IPM point falls on.
void AssignLanePixels(const WindowSnapshot& snapshot, const BackendOptions& options,
                      WindowState* state) {
  const Ipm ipm(PinholeCamera(snapshot.camera), snapshot.T_base_cam, 1e9);
  for (std::size_t l = 0; l < snapshot.lanes.size(); ++l) {
    const WindowLane& lane = snapshot.lanes[l];
    if (lane.control_points_map.size() < 4) continue;
    const CatmullRomSpline spline(lane.control_points_map);
    for (const LaneMeasurement& m : lane.measurements) {
      const auto slot = state->slot_of_frame.find(m.frame_index);
      if (slot == state->slot_of_frame.end()) continue;
      const Eigen::Isometry3d T_map_base = snapshot.frames[slot->second].T_map_base;
      int used = 0;
      for (std::size_t i = 0; i < m.points.size(); ++i) {
        if (!m.selected[i] || used >= options.max_lane_points_per_observation) continue;
        Eigen::Vector3d p_base;
        if (ipm.PixelToGround(m.points[i].uv, &p_base) != IpmStatus::kOk) continue;
        const Eigen::Vector3d p_map = T_map_base * p_base;
        const CatmullRomSpline::ClosestPoint closest = spline.FindClosest(p_map);
        if (closest.distance_m > kMaxLanePixelDistanceM) continue;
        if (closest.s <= 0.0 || closest.s >= spline.NumSegments()) continue;  // past an end
        state->lane_pixels.push_back(
            {l, slot->second, m.points[i].uv, closest.segment, closest.u, p_map});
        ++used;
      }
    }
  }
}

ceres::LossFunction* MakeLoss(const BackendOptions& options) {
  if (options.robust_kernel == "huber") return new ceres::HuberLoss(options.robust_scale);
  if (options.robust_kernel == "cauchy") return new ceres::CauchyLoss(options.robust_scale);
  return nullptr;
}

// Adds the measurement residuals shared by both steps (corner reprojection and the lane
// residual). Returns the number of residual blocks added.
int AddMeasurementResiduals(const WindowSnapshot& snapshot, const BackendOptions& options,
                            WindowState* state, ceres::Problem* problem,
                            ceres::LossFunction* loss) {
  const PinholeCamera camera(snapshot.camera);
  int blocks = 0;
  double* q_bc = state->extrinsic.q;
  double* t_bc = state->extrinsic.t;
  for (std::size_t m = 0; m < snapshot.markings.size(); ++m) {
    for (const MarkingMeasurement& meas : snapshot.markings[m].measurements) {
      const auto slot = state->slot_of_frame.find(meas.frame_index);
      if (slot == state->slot_of_frame.end()) continue;
      PoseBlocks& pose = state->frames[slot->second];
      for (int c = 0; c < 4; ++c) {
        problem->AddResidualBlock(residuals::CornerReprojectionResidual::Create(
                                      camera, meas.corners_uv[c], options.pixel_sigma_px),
                                  loss, state->corners[m][c].data(), pose.q, pose.t, q_bc, t_bc);
        ++blocks;
      }
    }
  }
  for (const LanePixel& px : state->lane_pixels) {
    auto& cps = state->control_points[px.lane];
    PoseBlocks& pose = state->frames[px.frame_slot];
    if (options.lane_residual == LaneResidual::kPpsr) {
      problem->AddResidualBlock(
          residuals::PpsrResidual::Create(camera, px.uv, options.pixel_sigma_px), loss,
          cps[px.segment + 1].data(), cps[px.segment + 2].data(), pose.q, pose.t, q_bc, t_bc);
      ++blocks;
    } else if (options.lane_residual == LaneResidual::kPsr) {
      problem->AddResidualBlock(residuals::PsrResidual::Create(px.q_map, px.u, options.psr_sigma_m),
                                loss, cps[px.segment].data(), cps[px.segment + 1].data(),
                                cps[px.segment + 2].data(), cps[px.segment + 3].data());
      ++blocks;
    }
  }
  return blocks;
}

// Marks each used 3D point block: constant, or free with z held when optimize_z is off.
void ConfigurePointBlock(ceres::Problem* problem, double* point, bool free, bool optimize_z) {
  if (!problem->HasParameterBlock(point)) return;
  if (!free) {
    problem->SetParameterBlockConstant(point);
  } else if (!optimize_z) {
    problem->SetManifold(point, new ceres::SubsetManifold(3, {2}));
  }
}

void ConfigurePose(ceres::Problem* problem, PoseBlocks* pose, bool free) {
  if (problem->HasParameterBlock(pose->q)) {
    problem->SetManifold(pose->q, new ceres::EigenQuaternionManifold);
    if (!free) problem->SetParameterBlockConstant(pose->q);
  }
  if (problem->HasParameterBlock(pose->t) && !free) problem->SetParameterBlockConstant(pose->t);
}

ceres::Solver::Summary Solve(const BackendOptions& options, ceres::Problem* problem) {
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  solver.max_num_iterations = options.max_iterations;
  solver.num_threads = 1;
  solver.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  if (problem->NumResidualBlocks() > 0) ceres::Solve(solver, problem, &summary);
  return summary;
}

// The pose (of the window's frames) from which `p_map` was seen closest, among `frames`.
const Eigen::Isometry3d* ClosestFrame(const WindowSnapshot& snapshot,
                                      const std::vector<std::size_t>& frame_indices,
                                      const WindowState& state, const Eigen::Vector3d& p_map) {
  const Eigen::Isometry3d* best = nullptr;
  double best_distance = 1e18;
  for (std::size_t index : frame_indices) {
    const auto slot = state.slot_of_frame.find(index);
    if (slot == state.slot_of_frame.end()) continue;
    const Eigen::Isometry3d& T = snapshot.frames[slot->second].T_map_base;
    const double d = (T.translation() - p_map).head<2>().norm();
    if (d < best_distance) {
      best_distance = d;
      best = &T;
    }
  }
  return best;
}

// Ground-height priors for every free map point (see ground_height_prior_residual.h).
void AddGroundHeightPriors(const WindowSnapshot& snapshot, const BackendOptions& options,
                           WindowState* state, ceres::Problem* problem) {
  for (std::size_t m = 0; m < snapshot.markings.size() && options.optimize_markings; ++m) {
    std::vector<std::size_t> frames;
    for (const auto& meas : snapshot.markings[m].measurements) frames.push_back(meas.frame_index);
    for (auto& c : state->corners[m]) {
      if (!problem->HasParameterBlock(c.data())) continue;
      if (const Eigen::Isometry3d* T = ClosestFrame(snapshot, frames, *state, c)) {
        problem->AddResidualBlock(
            residuals::GroundHeightPriorResidual::Create(*T, options.ground_height_sigma_m),
            nullptr, c.data());
      }
    }
  }
  if (options.lane_residual == LaneResidual::kNone) return;
  for (std::size_t l = 0; l < snapshot.lanes.size(); ++l) {
    std::vector<std::size_t> frames;
    for (const auto& meas : snapshot.lanes[l].measurements) frames.push_back(meas.frame_index);
    for (auto& c : state->control_points[l]) {
      if (!problem->HasParameterBlock(c.data())) continue;
      if (const Eigen::Isometry3d* T = ClosestFrame(snapshot, frames, *state, c)) {
        problem->AddResidualBlock(
            residuals::GroundHeightPriorResidual::Create(*T, options.ground_height_sigma_m),
            nullptr, c.data());
      }
    }
  }
}

// The map + extrinsic step. Returns the summary.
ceres::Solver::Summary MapStep(const WindowSnapshot& snapshot, const BackendOptions& options,
                               WindowState* state, int* blocks) {
  ceres::Problem problem;
  ceres::LossFunction* loss = MakeLoss(options);
  *blocks = AddMeasurementResiduals(snapshot, options, state, &problem, loss);
  if (*blocks == 0) {
    delete loss;
    return ceres::Solver::Summary();
  }
  problem.AddResidualBlock(residuals::TranslationPriorResidual::Create(
                               snapshot.t_base_cam_prior, options.translation_prior_sigma_m),
                           nullptr, state->extrinsic.t);
  problem.AddResidualBlock(residuals::RotationPriorResidual::Create(
                               snapshot.q_base_cam_prior, options.rotation_prior_sigma_rad),
                           nullptr, state->extrinsic.q);
  const bool lanes_free = options.lane_residual != LaneResidual::kNone;
  for (auto& cps : state->control_points) {
    for (auto& c : cps) {
      if (!lanes_free || !problem.HasParameterBlock(c.data())) continue;
      problem.AddResidualBlock(
          residuals::PointAnchorResidual::Create(c, kControlPointAnchorSigmaM), nullptr, c.data());
    }
  }
  if (options.ground_height_sigma_m > 0.0 && options.optimize_z) {
    AddGroundHeightPriors(snapshot, options, state, &problem);
  }
  for (auto& corners : state->corners) {
    for (auto& c : corners) {
      ConfigurePointBlock(&problem, c.data(), options.optimize_markings, options.optimize_z);
    }
  }
  for (auto& cps : state->control_points) {
    for (auto& c : cps) ConfigurePointBlock(&problem, c.data(), lanes_free, options.optimize_z);
  }
  for (PoseBlocks& pose : state->frames) ConfigurePose(&problem, &pose, false);
  // The extrinsic: rotation on the quaternion manifold; held when not optimized.
  problem.SetManifold(state->extrinsic.q, new ceres::EigenQuaternionManifold);
  if (!options.optimize_extrinsic) {
    problem.SetParameterBlockConstant(state->extrinsic.q);
    problem.SetParameterBlockConstant(state->extrinsic.t);
  }
  return Solve(options, &problem);
}

// The pose-update step.
ceres::Solver::Summary PoseStep(const WindowSnapshot& snapshot, const BackendOptions& options,
                                WindowState* state, int* blocks) {
  ceres::Problem problem;
  ceres::LossFunction* loss = MakeLoss(options);
  *blocks = AddMeasurementResiduals(snapshot, options, state, &problem, loss);
  if (*blocks == 0) {
    delete loss;
    return ceres::Solver::Summary();
  }
  for (std::size_t i = 0; i < state->frames.size(); ++i) {
    PoseBlocks& pose = state->frames[i];
    if (!problem.HasParameterBlock(pose.q)) continue;
    problem.AddResidualBlock(
        residuals::PosePriorResidual::Create(snapshot.frames[i].T_map_base_odom,
                                             options.pose_prior_sigma_trans_m,
                                             options.pose_prior_sigma_rot_rad),
        nullptr, pose.q, pose.t);
    ConfigurePose(&problem, &pose, true);
  }
  for (auto& corners : state->corners) {
    for (auto& c : corners) ConfigurePointBlock(&problem, c.data(), false, true);
  }
  for (auto& cps : state->control_points) {
    for (auto& c : cps) ConfigurePointBlock(&problem, c.data(), false, true);
  }
  problem.SetManifold(state->extrinsic.q, new ceres::EigenQuaternionManifold);
  problem.SetParameterBlockConstant(state->extrinsic.q);
  problem.SetParameterBlockConstant(state->extrinsic.t);
  return Solve(options, &problem);
}

}  // namespace

WindowResult SolveWindow(const WindowSnapshot& snapshot, const BackendOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  WindowResult result;
  result.sequence = snapshot.sequence;
  WindowState state(snapshot);
  if (options.lane_residual != LaneResidual::kNone) AssignLanePixels(snapshot, options, &state);

  bool usable = true;
  for (int round = 0; round < options.rounds && usable; ++round) {
    int blocks = 0;
    ceres::Solver::Summary summary = MapStep(snapshot, options, &state, &blocks);
    result.residual_blocks = std::max(result.residual_blocks, blocks);
    if (blocks > 0) {
      usable = summary.IsSolutionUsable();
      result.iterations += static_cast<int>(summary.iterations.size());
      if (round == 0) result.initial_cost = summary.initial_cost;
      result.final_cost = summary.final_cost;
      result.summary = summary.BriefReport();
    }
    if (usable && options.pose_update) {
      summary = PoseStep(snapshot, options, &state, &blocks);
      if (blocks > 0) {
        usable = summary.IsSolutionUsable();
        result.iterations += static_cast<int>(summary.iterations.size());
        result.final_cost = summary.final_cost;
      }
    }
  }

  result.T_base_cam = state.extrinsic.ToIsometry();
  result.extrinsic_change_rad = RotationAngleBetween(result.T_base_cam, snapshot.T_base_cam);
  result.extrinsic_change_m =
      (result.T_base_cam.translation() - snapshot.T_base_cam.translation()).norm();
  if (!usable) {
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
    result.frames.push_back(frame);
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
