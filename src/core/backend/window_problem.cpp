#include "ipm_road_mapper/core/backend/window_problem.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <optional>

#include "ipm_road_mapper/core/backend/extrinsic_observability.h"
#include "ipm_road_mapper/core/backend/residuals/along_lane_anchor_residual.h"
#include "ipm_road_mapper/core/backend/residuals/corner_reprojection_residual.h"
#include "ipm_road_mapper/core/backend/residuals/edge_reprojection_residual.h"
#include "ipm_road_mapper/core/backend/residuals/extrinsic_prior_residual.h"
#include "ipm_road_mapper/core/backend/residuals/lane_smoothness_residual.h"
#include "ipm_road_mapper/core/backend/residuals/motion_prior_residual.h"
#include "ipm_road_mapper/core/backend/residuals/pose_prior_residual.h"
#include "ipm_road_mapper/core/backend/residuals/pose_uncertainty.h"
#include "ipm_road_mapper/core/backend/residuals/ppsr_residual.h"
#include "ipm_road_mapper/core/backend/residuals/psr_residual.h"
#include "ipm_road_mapper/core/backend/residuals/road_surface_prior_residual.h"
#include "ipm_road_mapper/core/frontend/marking_measurement.h"
#include "ipm_road_mapper/core/geometry/catmull_rom_spline.h"
#include "ipm_road_mapper/core/geometry/ipm.h"
#include "ipm_road_mapper/core/geometry/rigid_transform.h"
#include "ipm_road_mapper/core/geometry/road_surface.h"

namespace ipm_road_mapper {
namespace {

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

// One marking corner measurement: which marking, corner and frame slot.
struct CornerMeasurement {
  std::size_t marking = 0;
  int corner = 0;
  std::size_t slot = 0;
  Eigen::Vector2d uv;
};

// One pixel on a measured side of a partial view whose corner the view cut (the edge
// residual): which marking, side (corners side and side + 1) and frame slot.
struct EdgeMeasurement {
  std::size_t marking = 0;
  int side = 0;
  std::size_t slot = 0;
  Eigen::Vector2d uv;
};

// One lane pixel: which lane, frame slot and spline segment (the segment's control points
// are c[segment] .. c[segment + 3]; PPSR uses c[segment + 1], c[segment + 2]).
struct LanePixel {
  std::size_t lane = 0;
  std::size_t slot = 0;
  Eigen::Vector2d uv;
  int segment = 0;
  double u = 0.0;
  Eigen::Vector3d q_map;  // IPM point at build time (PSR)
};

// The mutable state of one solve, initialized from the snapshot, and the measurements that
// survived the build-time checks.
struct WindowState {
  PoseBlocks extrinsic;
  std::vector<PoseBlocks> frames;
  std::map<std::size_t, std::size_t> slot_of_frame;
  std::vector<std::array<Eigen::Vector3d, 4>> corners;
  std::vector<std::vector<Eigen::Vector3d>> control_points;
  std::vector<CornerMeasurement> corner_measurements;
  std::vector<EdgeMeasurement> edge_measurements;
  PoseBlocks held_extrinsic;  // the extrinsic as partial-only markings see it (held)
  std::vector<LanePixel> lane_pixels;
  std::vector<Eigen::Isometry3d> poses;  // the frames' poses at the start (road surface)
  std::vector<bool> optimized;           // free in a pose step (WindowFrame::optimized)
  int covariance_slot = -1;              // the newest optimized frame after the last pose step
  PoseCovariance covariance = PoseCovariance::Zero();                  // of that frame's pose
  double step_time_limit_s = std::numeric_limits<double>::infinity();  // of the next step
  // The extrinsic guard (BackendOptions::extrinsic_holdout_every_n_frames): the frames whose
  // measurements the map step leaves out while `hold_out` is set, and whether the
  // extrinsic is held at its value (the guard's reference fit, or after a rejection).
  std::vector<bool> held_out;
  bool hold_out = false;
  bool extrinsic_frozen = false;
  // What the last map step with the extrinsic free found about it.
  ExtrinsicObservability observability;
  bool observability_valid = false;
  explicit WindowState(const WindowSnapshot& s)
      : extrinsic(s.T_base_cam), held_extrinsic(s.T_base_cam) {
    for (std::size_t i = 0; i < s.frames.size(); ++i) {
      frames.emplace_back(s.frames[i].T_map_base);
      poses.push_back(s.frames[i].T_map_base);
      slot_of_frame[s.frames[i].index] = i;
      held_out.push_back(false);
    }
    optimized.assign(s.frames.size(), false);
    for (const WindowMarking& m : s.markings) corners.push_back(m.corners_map);
    for (const WindowLane& l : s.lanes) control_points.push_back(l.control_points_map);
  }
};

// True when p_map projects in front of the camera of `slot`, at most margin_px outside the
// image (BackendOptions::max_outside_image_px).
bool ProjectsNearImage(const PinholeCamera& camera, const WindowState& state, std::size_t slot,
                       const Eigen::Vector3d& p_map, double margin_px) {
  Eigen::Vector2d uv;
  if (!residuals::ProjectMapPoint(camera, state.frames[slot].q, state.frames[slot].t,
                                  state.extrinsic.q, state.extrinsic.t, p_map, &uv)) {
    return false;
  }
  const double m = margin_px;
  return uv.x() > -m && uv.y() > -m && uv.x() < camera.intrinsics().width + m &&
         uv.y() < camera.intrinsics().height + m;
}

// Collects the corner measurements of the window's frames, each re-measured from its
// outline on the road plane at the marking (road_surface.h, from the window's frames; see
// marking_measurement.h; the flat-ground corners are the fallback).
void CollectCornerMeasurements(const WindowSnapshot& snapshot, const BackendOptions& options,
                               WindowState* state) {
  const PinholeCamera camera(snapshot.camera);
  const Eigen::Isometry3d T_base_cam = state->extrinsic.ToIsometry();
  for (std::size_t m = 0; m < snapshot.markings.size(); ++m) {
    const auto& corners = state->corners[m];
    const Eigen::Vector3d center = 0.25 * (corners[0] + corners[1] + corners[2] + corners[3]);
    const RoadPlane plane =
        RoadSurfaceNear(state->poses, center, options.road_plane_radius_m).plane;
    const Eigen::Vector3d& axis = snapshot.markings[m].axis_map;
    const auto& measurements = snapshot.markings[m].measurements;
    // Partial views measure a marking no whole view shows (one larger than the view); where
    // whole views exist they alone are measurements (see docs/backend.md, "Partial views").
    const bool seen_whole =
        std::any_of(measurements.begin(), measurements.end(),
                    [](const MarkingMeasurement& meas) { return meas.Complete(); });
    std::vector<std::size_t> usable;
    for (std::size_t i = 0; i < measurements.size(); ++i) {
      if (!seen_whole || measurements[i].Complete()) usable.push_back(i);
    }
    // At most max_measurements_per_marking of them, spread over the history (the first and
    // the last included): neighbouring frames see a marking almost alike.
    const std::size_t cap = static_cast<std::size_t>(options.max_measurements_per_marking);
    std::vector<std::size_t> chosen;
    if (usable.size() <= cap) {
      chosen = usable;
    } else {
      for (std::size_t k = 0; k < cap; ++k) {
        chosen.push_back(usable[k * (usable.size() - 1) / (cap - 1)]);
      }
    }
    for (std::size_t i : chosen) {
      const MarkingMeasurement& meas = measurements[i];
      const auto slot = state->slot_of_frame.find(meas.frame_index);
      if (slot == state->slot_of_frame.end()) continue;
      std::array<Eigen::Vector2d, 4> corners_uv = meas.corners_uv;
      // Whole views are re-measured on the road plane; a partial view keeps its corners as
      // labeled (its rectangle on another plane could move a cut side onto a measured one).
      if (meas.Complete() && !meas.outline_uv.empty() && axis.norm() > 0.0) {
        const Eigen::Isometry3d T_map_cam = state->frames[slot->second].ToIsometry() * T_base_cam;
        std::array<Eigen::Vector2d, 4> on_plane;
        if (MeasureCornersOnPlane(camera, T_map_cam, plane, axis, corners, meas.outline_uv,
                                  &on_plane)) {
          corners_uv = on_plane;
        }
      }
      for (int c = 0; c < 4; ++c) {
        // A cut corner is no measurement (partial views): its sides may still be.
        if (!meas.CornerMeasured(c) || !corners_uv[c].allFinite()) continue;
        if (!ProjectsNearImage(camera, *state, slot->second, corners[c],
                               options.max_outside_image_px))
          continue;
        state->corner_measurements.push_back({m, c, slot->second, corners_uv[c]});
      }
      for (int side = 0; side < 4; ++side) {
        if (!meas.side_measured[side]) continue;
        if (meas.CornerMeasured(side) && meas.CornerMeasured((side + 1) % 4)) continue;
        for (const Eigen::Vector2d& uv : meas.side_uv[side]) {
          state->edge_measurements.push_back({m, side, slot->second, uv});
        }
      }
    }
  }
}

// Assigns each selected lane pixel of the window to the spline segment its IPM point falls
// on (at most max_lane_points_per_observation per observation, spread over its points).
void CollectLanePixels(const WindowSnapshot& snapshot, const BackendOptions& options,
                       WindowState* state) {
  const PinholeCamera camera(snapshot.camera);
  const Ipm ipm(camera, snapshot.T_base_cam, 1e9);
  for (std::size_t l = 0; l < snapshot.lanes.size(); ++l) {
    const WindowLane& lane = snapshot.lanes[l];
    if (lane.control_points_map.size() < 4) continue;
    const CatmullRomSpline spline(lane.control_points_map);
    for (const LaneMeasurement& m : lane.measurements) {
      const auto slot = state->slot_of_frame.find(m.frame_index);
      if (slot == state->slot_of_frame.end()) continue;
      std::vector<std::size_t> selected;
      for (std::size_t i = 0; i < m.points.size(); ++i) {
        if (m.selected[i]) selected.push_back(i);
      }
      const std::size_t cap = static_cast<std::size_t>(options.max_lane_points_per_observation);
      const double step = selected.size() > cap ? static_cast<double>(selected.size()) / cap : 1.0;
      const Eigen::Isometry3d T_map_base = state->frames[slot->second].ToIsometry();
      for (double k = 0.0; k < static_cast<double>(selected.size()); k += step) {
        const LanePoint& point = m.points[selected[static_cast<std::size_t>(k)]];
        Eigen::Vector3d p_base;
        if (ipm.PixelToGround(point.uv, &p_base) != IpmStatus::kOk) continue;
        const Eigen::Vector3d p_map = T_map_base * p_base;
        const CatmullRomSpline::ClosestPoint closest = spline.FindClosest(p_map);
        if (closest.distance_m > options.max_lane_pixel_distance_m) continue;
        if (closest.s <= 0.0 || closest.s >= spline.NumSegments()) continue;  // past an end
        const auto& cps = lane.control_points_map;
        if (!ProjectsNearImage(camera, *state, slot->second, cps[closest.segment + 1],
                               options.max_outside_image_px) ||
            !ProjectsNearImage(camera, *state, slot->second, cps[closest.segment + 2],
                               options.max_outside_image_px)) {
          continue;
        }
        state->lane_pixels.push_back(
            {l, slot->second, point.uv, closest.segment, closest.u, p_map});
      }
    }
  }
}

ceres::LossFunction* MakeLoss(const BackendOptions& options) {
  switch (options.robust_kernel) {
    case RobustKernel::kHuber:
      return new ceres::HuberLoss(options.robust_scale);
    case RobustKernel::kCauchy:
      return new ceres::CauchyLoss(options.robust_scale);
    case RobustKernel::kNone:
      return nullptr;
  }
  return nullptr;
}

// The road-surface prior of a map point (road_surface_prior_residual.h): on the road plane
// of the window's frames near it, with a sigma that grows with how far that plane is
// extrapolated (the road is known where the wheels were, less so ahead of them).
void AddRoadSurfacePrior(const BackendOptions& options, const WindowState& state, double* point,
                         ceres::Problem* problem) {
  const RoadSurfaceEstimate road = RoadSurfaceNear(
      state.poses, Eigen::Vector3d(point[0], point[1], point[2]), options.road_plane_radius_m);
  const double sigma =
      std::hypot(options.road_height_sigma_m, options.road_height_sigma_per_m * road.distance_m);
  problem->AddResidualBlock(residuals::RoadSurfacePriorResidual::Create(road.plane, sigma), nullptr,
                            point);
}

// Free 3D map point: z held by a subset manifold when optimize_z is off.
void ConfigurePoint(const BackendOptions& options, double* point, ceres::Problem* problem) {
  if (!options.optimize_z) problem->SetManifold(point, new ceres::SubsetManifold(3, {2}));
}

ceres::Solver::Summary Solve(const BackendOptions& options, double time_limit_s,
                             ceres::Problem* problem) {
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  solver.max_num_iterations = options.max_iterations;
  if (std::isfinite(time_limit_s)) solver.max_solver_time_in_seconds = std::max(0.0, time_limit_s);
  solver.num_threads = 1;
  solver.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  if (problem->NumResidualBlocks() > 0) ceres::Solve(solver, problem, &summary);
  return summary;
}

// The priors of the free map points (what makes them well posed besides the measurements):
// on the road surface (softly), z optionally held; control points anchored along their lane
// (PPSR leaves that direction free: a gauge of each point) and smooth.
void AddMapPointPriors(const BackendOptions& options, WindowState* state,
                       ceres::Problem* problem_ptr) {
  ceres::Problem& problem = *problem_ptr;
  // A corner that only edge residuals reach slides along its side at no cost: held loosely
  // where it is (isotropic lane_anchor_across_sigma_m, as a lane's control point across its
  // lane), the edges decide across the side.
  std::vector<std::array<bool, 4>> has_corner_pixel(state->corners.size(),
                                                    {{false, false, false, false}});
  for (const CornerMeasurement& m : state->corner_measurements) {
    has_corner_pixel[m.marking][m.corner] = true;
  }
  for (std::size_t k = 0; k < state->corners.size(); ++k) {
    for (int i = 0; i < 4; ++i) {
      auto& c = state->corners[k][i];
      if (!problem.HasParameterBlock(c.data())) continue;
      if (!has_corner_pixel[k][i]) {
        problem.AddResidualBlock(residuals::AlongLaneAnchorResidual::Create(
                                     c, Eigen::Vector3d::Zero(), options.lane_anchor_along_sigma_m,
                                     options.lane_anchor_across_sigma_m),
                                 nullptr, c.data());
      }
      if (options.optimize_z) AddRoadSurfacePrior(options, *state, c.data(), &problem);
      ConfigurePoint(options, c.data(), &problem);
    }
  }
  for (auto& cps : state->control_points) {
    // Smoothness over every triple that touches a free point (the others join as data).
    std::vector<bool> free(cps.size());
    for (std::size_t j = 0; j < cps.size(); ++j) free[j] = problem.HasParameterBlock(cps[j].data());
    if (options.lane_smoothness_sigma_m > 0.0) {
      for (std::size_t j = 1; j + 1 < cps.size(); ++j) {
        if (!free[j - 1] && !free[j] && !free[j + 1]) continue;
        problem.AddResidualBlock(
            residuals::LaneSmoothnessResidual::Create(options.lane_smoothness_sigma_m), nullptr,
            cps[j - 1].data(), cps[j].data(), cps[j + 1].data());
        for (std::size_t k = j - 1; k <= j + 1; ++k) {
          if (!free[k]) problem.SetParameterBlockConstant(cps[k].data());
        }
      }
    }
    for (std::size_t j = 0; j < cps.size(); ++j) {
      auto& c = cps[j];
      if (!free[j]) continue;
      const Eigen::Vector3d tangent = cps[std::min(j + 1, cps.size() - 1)] - cps[j > 0 ? j - 1 : 0];
      problem.AddResidualBlock(
          residuals::AlongLaneAnchorResidual::Create(c, tangent, options.lane_anchor_along_sigma_m,
                                                     options.lane_anchor_across_sigma_m),
          nullptr, c.data());
      if (options.optimize_z) AddRoadSurfacePrior(options, *state, c.data(), &problem);
      ConfigurePoint(options, c.data(), &problem);
    }
  }
}

// Weight of the hold on an unobserved direction, in whitened units (times the mounting
// prior's information): the direction stays within 1 % of a prior sigma of its start value.
constexpr double kUnobservedHoldWeight = 1e4;

// The observability-aware update (extrinsic_observability.h): each direction the solve's
// data does not observe (ObserveExtrinsic) is held at the window's starting extrinsic.
void HoldUnobservedDirections(const WindowSnapshot& snapshot, const BackendOptions& options,
                              const WindowState& state, ceres::Problem* problem) {
  if (!options.extrinsic_hold_unobserved) return;
  if (!state.observability_valid || state.observability.rank == 6) return;
  const Eigen::Quaterniond q0 = Eigen::Quaterniond(snapshot.T_base_cam.linear()).normalized();
  problem->AddResidualBlock(
      residuals::ExtrinsicPriorResidual::Create(
          q0, snapshot.T_base_cam.translation(),
          state.observability.UnobservedHoldSqrtInformation(kUnobservedHoldWeight),
          Vector6d::Zero()),
      nullptr, const_cast<double*>(state.extrinsic.q), const_cast<double*>(state.extrinsic.t));
}

// Which of a state's measurements a problem gets.
enum class Measurements { kTraining, kHeldOut, kAll };

// Adds the corner and lane-pixel residuals of the map step (pixel sigma and pose uncertainty,
// pose_uncertainty.h; poses as data) for the chosen measurements; returns how many.
int AddMapStepMeasurements(const WindowSnapshot& snapshot, const BackendOptions& options,
                           Measurements which, ceres::LossFunction* loss, WindowState* state,
                           ceres::Problem* problem) {
  const PinholeCamera camera(snapshot.camera);
  double* q_bc = state->extrinsic.q;
  double* t_bc = state->extrinsic.t;
  int blocks = 0;
  auto wanted = [&](std::size_t slot) {
    return which == Measurements::kAll ||
           (which == Measurements::kHeldOut) == state->held_out[slot];
  };
  // The poses are data here, but uncertain: their sigma joins the pixels' (pose_uncertainty.h).
  const Eigen::Isometry3d T_base_cam = state->extrinsic.ToIsometry();
  const Eigen::Vector3d sigma_t =
      options.map_step_pose_sigma_scale * options.pose_prior_sigma_trans_m;
  const Eigen::Vector3d sigma_r =
      options.map_step_pose_sigma_scale * options.pose_prior_sigma_rot_rad;
  auto whitening = [&](std::size_t slot, const Eigen::Vector3d& p_map) {
    return residuals::PoseUncertaintyWhitening(camera, state->poses[slot], T_base_cam, p_map,
                                               options.pixel_sigma_px, sigma_t, sigma_r);
  };
  // Markings seen only in partial views see the extrinsic through a held copy (docs/backend.md,
  // "Partial views"): they are refined, but never move the extrinsic.
  state->held_extrinsic = state->extrinsic;
  bool extrinsic_held_used = false;
  auto extrinsic_for = [&](std::size_t marking, double** q, double** t) {
    const bool held = snapshot.markings[marking].partial_only;
    extrinsic_held_used = extrinsic_held_used || held;
    *q = held ? state->held_extrinsic.q : q_bc;
    *t = held ? state->held_extrinsic.t : t_bc;
  };
  if (options.optimize_markings) {
    for (const CornerMeasurement& m : state->corner_measurements) {
      if (!wanted(m.slot)) continue;
      const PoseBlocks& pose = state->frames[m.slot];
      auto& corner = state->corners[m.marking][m.corner];
      double *q = nullptr, *t = nullptr;
      extrinsic_for(m.marking, &q, &t);
      problem->AddResidualBlock(residuals::CornerReprojectionMapStepResidual::Create(
                                    camera, m.uv, whitening(m.slot, corner), pose.q, pose.t),
                                loss, corner.data(), q, t);
      ++blocks;
    }
    for (const EdgeMeasurement& m : state->edge_measurements) {
      if (!wanted(m.slot)) continue;
      const PoseBlocks& pose = state->frames[m.slot];
      auto& corners = state->corners[m.marking];
      double *q = nullptr, *t = nullptr;
      extrinsic_for(m.marking, &q, &t);
      problem->AddResidualBlock(residuals::EdgeReprojectionMapStepResidual::Create(
                                    camera, m.uv, options.pixel_sigma_px, pose.q, pose.t),
                                loss, corners[m.side].data(), corners[(m.side + 1) % 4].data(), q,
                                t);
      ++blocks;
    }
  }
  if (extrinsic_held_used) {
    problem->SetManifold(state->held_extrinsic.q, new ceres::EigenQuaternionManifold);
    problem->SetParameterBlockConstant(state->held_extrinsic.q);
    problem->SetParameterBlockConstant(state->held_extrinsic.t);
  }
  for (const LanePixel& px : state->lane_pixels) {
    if (!wanted(px.slot)) continue;
    auto& cps = state->control_points[px.lane];
    const PoseBlocks& pose = state->frames[px.slot];
    if (options.lane_residual == LaneResidual::kPpsr) {
      problem->AddResidualBlock(
          residuals::PpsrMapStepResidual::Create(
              camera, px.uv, whitening(px.slot, cps[px.segment + 1]), pose.q, pose.t),
          loss, cps[px.segment + 1].data(), cps[px.segment + 2].data(), q_bc, t_bc);
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

// The map + extrinsic step: marking corners, lane control points and the extrinsic free,
// the window's poses data (which also fixes the gauge: the map hangs on the poses).
ceres::Solver::Summary MapStep(const WindowSnapshot& snapshot, const BackendOptions& options,
                               WindowState* state, int* blocks) {
  ceres::Problem problem;
  ceres::LossFunction* loss = MakeLoss(options);
  double* q_bc = state->extrinsic.q;
  double* t_bc = state->extrinsic.t;
  *blocks = AddMapStepMeasurements(snapshot, options,
                                   state->hold_out ? Measurements::kTraining : Measurements::kAll,
                                   loss, state, &problem);
  if (*blocks == 0) {
    delete loss;
    return ceres::Solver::Summary();
  }
  AddMapPointPriors(options, state, &problem);
  // The extrinsic: the prior of the retired data and the mounting (counted there once),
  // rotation on the quaternion manifold; held when not optimized, and in the directions the
  // data does not observe.
  if (problem.HasParameterBlock(q_bc)) {
    problem.AddResidualBlock(residuals::ExtrinsicPriorResidual::Create(snapshot.extrinsic_prior),
                             nullptr, q_bc, t_bc);
    problem.SetManifold(q_bc, new ceres::EigenQuaternionManifold);
    if (!options.optimize_extrinsic || state->extrinsic_frozen) {
      problem.SetParameterBlockConstant(q_bc);
      problem.SetParameterBlockConstant(t_bc);
    } else {
      HoldUnobservedDirections(snapshot, options, *state, &problem);
    }
  }
  return Solve(options, state->step_time_limit_s, &problem);
}

// The total robustified cost of the held-out measurements at the state's map, extrinsic and
// poses: the evidence the guard judges an extrinsic by.
// (Per held-out measurement, in the order they were added: the same order for any state of
// one snapshot.)
std::vector<double> HeldOutCosts(const WindowSnapshot& snapshot, const BackendOptions& options,
                                 WindowState* state) {
  ceres::Problem problem;
  ceres::LossFunction* loss = MakeLoss(options);
  const int blocks =
      AddMapStepMeasurements(snapshot, options, Measurements::kHeldOut, loss, state, &problem);
  if (blocks == 0) delete loss;  // the problem owns it only through a residual block
  std::vector<ceres::ResidualBlockId> ids;
  problem.GetResidualBlocks(&ids);
  std::vector<double> costs;
  for (ceres::ResidualBlockId id : ids) {
    double cost = 0.0;
    problem.EvaluateResidualBlock(id, true, &cost, nullptr, nullptr);
    costs.push_back(cost);
  }
  return costs;
}

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

// The pose-update step: the window's poses free with their odometry priors; map and
// extrinsic data (the gauge is fixed by the map).
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
  // of a triple join as data.
  if (options.motion_prior) {
    for (std::size_t i = 1; i + 1 < state->frames.size(); ++i) {
      const WindowFrame& a = snapshot.frames[i - 1];
      const WindowFrame& b = snapshot.frames[i];
      const WindowFrame& c = snapshot.frames[i + 1];
      if (b.index != a.index + 1 || c.index != b.index + 1) continue;
      if (!problem.HasParameterBlock(state->frames[i].q)) continue;  // no data on the middle one
      const double dt_a = b.stamp - a.stamp, dt_b = c.stamp - b.stamp;
      if (!(dt_a > 0.0) || !(dt_b > 0.0)) continue;
      PoseBlocks &pa = state->frames[i - 1], &pb = state->frames[i], &pc = state->frames[i + 1];
      problem.AddResidualBlock(
          residuals::MotionPriorResidual::Create(dt_a, dt_b, options.motion_sigma_acc_mps2,
                                                 options.motion_sigma_angular_acc_radps2),
          nullptr, pa.q, pa.t, pb.q, pb.t, pc.q, pc.t);
    }
  }
  for (std::size_t i = 0; i < state->frames.size(); ++i) {
    PoseBlocks& pose = state->frames[i];
    if (!problem.HasParameterBlock(pose.q)) continue;
    if (!snapshot.frames[i].in_window) {  // a context frame: data
      problem.SetParameterBlockConstant(pose.q);
      problem.SetParameterBlockConstant(pose.t);
      continue;
    }
    problem.AddResidualBlock(
        residuals::PosePriorResidual::Create(snapshot.frames[i].T_map_base_odom,
                                             options.pose_prior_sigma_trans_m,
                                             options.pose_prior_sigma_rot_rad),
        nullptr, pose.q, pose.t);
    problem.SetManifold(pose.q, new ceres::EigenQuaternionManifold);
  }
  const ceres::Solver::Summary summary = Solve(options, state->step_time_limit_s, &problem);
  if (summary.IsSolutionUsable()) RecordPoseStep(snapshot, &problem, state);
  return summary;
}

// What the solve's data observes of the extrinsic (extrinsic_observability.h), at the
// state's start: the information of its map-step measurements (the held-out ones excluded)
// with the map points and the window's poses marginalized, each pose on its odometry and
// under the motion prior as in the pose step (context frames are data). Marginalizing the
// poses matters: the map step takes them as data, and a direction of the extrinsic that a
// pose error explains as well (the camera's yaw against the heading, with noisy odometry)
// is not observed.
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
  for (std::size_t i = 0; i < state->frames.size(); ++i) {
    PoseBlocks& pose = state->frames[i];
    if (!problem.HasParameterBlock(pose.q)) continue;
    problem.SetManifold(pose.q, new ceres::EigenQuaternionManifold);
    if (!snapshot.frames[i].in_window) {
      problem.SetParameterBlockConstant(pose.q);
      problem.SetParameterBlockConstant(pose.t);
      continue;
    }
    problem.AddResidualBlock(
        residuals::PosePriorResidual::Create(snapshot.frames[i].T_map_base_odom,
                                             options.pose_prior_sigma_trans_m,
                                             options.pose_prior_sigma_rot_rad),
        nullptr, pose.q, pose.t);
  }
  if (options.motion_prior) {
    for (std::size_t i = 1; i + 1 < state->frames.size(); ++i) {
      const WindowFrame& a = snapshot.frames[i - 1];
      const WindowFrame& b = snapshot.frames[i];
      const WindowFrame& c = snapshot.frames[i + 1];
      if (b.index != a.index + 1 || c.index != b.index + 1 || !b.in_window) continue;
      if (!problem.HasParameterBlock(state->frames[i - 1].q) ||
          !problem.HasParameterBlock(state->frames[i].q) ||
          !problem.HasParameterBlock(state->frames[i + 1].q)) {
        continue;
      }
      const double dt_a = b.stamp - a.stamp, dt_b = c.stamp - b.stamp;
      if (!(dt_a > 0.0) || !(dt_b > 0.0)) continue;
      PoseBlocks &pa = state->frames[i - 1], &pb = state->frames[i], &pc = state->frames[i + 1];
      problem.AddResidualBlock(
          residuals::MotionPriorResidual::Create(dt_a, dt_b, options.motion_sigma_acc_mps2,
                                                 options.motion_sigma_angular_acc_radps2),
          nullptr, pa.q, pa.t, pb.q, pb.t, pc.q, pc.t);
    }
  }
  problem.SetManifold(q_bc, new ceres::EigenQuaternionManifold);
  state->observability = AnalyzeObservability(
      ExtrinsicInformation(&problem, q_bc, t_bc, {}),
      PriorSigma(options.rotation_prior_sigma_rad, options.translation_prior_sigma_m),
      options.extrinsic_min_information_ratio);
  state->observability_valid = true;
}

// The guard against harm, after the first map step (the poses still the snapshot's): the
// refined extrinsic is kept unless it explains the held-out frames' measurements worse
// than the starting one (beyond their noise), each with the map re-fit to the training
// frames. Otherwise the
// state becomes the reference fit and the extrinsic stays held for the rest of the solve.
// Nothing is judged when no direction was updated.
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

// The extrinsic's calibration after the solve: which directions its data observed and the
// covariance of the prior plus that observed information.
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

}  // namespace

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
  FillCalibration(snapshot, state, &result);

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
