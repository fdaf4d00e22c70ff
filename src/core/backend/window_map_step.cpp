#include "ipm_road_mapper/core/backend/window_map_step.h"

#include <algorithm>
#include <cmath>

#include "ipm_road_mapper/core/backend/residuals/along_lane_anchor_residual.h"
#include "ipm_road_mapper/core/backend/residuals/corner_reprojection_residual.h"
#include "ipm_road_mapper/core/backend/residuals/crown_slope_prior_residual.h"
#include "ipm_road_mapper/core/backend/residuals/edge_reprojection_residual.h"
#include "ipm_road_mapper/core/backend/residuals/extrinsic_prior_residual.h"
#include "ipm_road_mapper/core/backend/residuals/lane_smoothness_residual.h"
#include "ipm_road_mapper/core/backend/residuals/pose_uncertainty.h"
#include "ipm_road_mapper/core/backend/residuals/ppsr_residual.h"
#include "ipm_road_mapper/core/backend/residuals/psr_residual.h"
#include "ipm_road_mapper/core/backend/residuals/road_cross_section_prior_residual.h"
#include "ipm_road_mapper/core/backend/residuals/road_surface_prior_residual.h"
#include "ipm_road_mapper/core/backend/window_measurements.h"
#include "ipm_road_mapper/core/geometry/road_surface.h"

namespace ipm_road_mapper {
namespace window_solve {
namespace {

// The road-surface prior of a map point (road_surface_prior_residual.h): on the road plane
// of the window's frames near it, with a sigma that grows with how far that plane is
// extrapolated (the road is known where the wheels were, less so ahead of them). With
// road_crown_slope_sigma, a point beyond road_crown_lateral_m across lies on its side's
// plane bent by that side's crown slope (road_cross_section_prior_residual.h).
void AddRoadSurfacePrior(const BackendOptions& options, WindowState* state, double* point,
                         ceres::Problem* problem) {
  const RoadSurfaceEstimate road = RoadSurfaceNear(
      state->poses, Eigen::Vector3d(point[0], point[1], point[2]), options.road_plane_radius_m);
  const double sigma =
      std::hypot(options.road_height_sigma_m, options.road_height_sigma_per_m * road.distance_m);
  const double beyond_m = std::abs(road.lateral_m) - options.road_crown_lateral_m;
  if (options.road_crown_slope_sigma > 0.0 && road.frames > 0 && beyond_m > 0.0) {
    double* kappa = &state->crown_slope[road.lateral_m > 0.0 ? 0 : 1];
    if (!problem->HasParameterBlock(kappa)) {
      problem->AddResidualBlock(
          residuals::CrownSlopePriorResidual::Create(options.road_crown_slope_sigma), nullptr,
          kappa);
    }
    problem->AddResidualBlock(
        residuals::RoadCrossSectionPriorResidual::Create(road.plane, beyond_m, sigma), nullptr,
        point, kappa);
    return;
  }
  problem->AddResidualBlock(residuals::RoadSurfacePriorResidual::Create(road.plane, sigma), nullptr,
                            point);
}

// Free 3D map point: z held by a subset manifold when optimize_z is off.
void ConfigurePoint(const BackendOptions& options, double* point, ceres::Problem* problem) {
  if (!options.optimize_z) problem->SetManifold(point, new ceres::SubsetManifold(3, {2}));
}

}  // namespace

void HoldUnobservedDirections(const ExtrinsicObservability& observability,
                              const Eigen::Isometry3d& T_base_cam_start, WindowState* state,
                              ceres::Problem* problem) {
  if (observability.rank == 6) return;
  const Eigen::Quaterniond q0 = Eigen::Quaterniond(T_base_cam_start.linear()).normalized();
  problem->AddResidualBlock(
      residuals::ExtrinsicPriorResidual::Create(
          q0, T_base_cam_start.translation(),
          observability.UnobservedHoldSqrtInformation(kUnobservedHoldWeight), Vector6d::Zero()),
      nullptr, state->extrinsic.q, state->extrinsic.t);
}

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
      if (options.optimize_z) AddRoadSurfacePrior(options, state, c.data(), &problem);
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
      if (options.optimize_z) AddRoadSurfacePrior(options, state, c.data(), &problem);
      ConfigurePoint(options, c.data(), &problem);
    }
  }
}

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

ceres::Solver::Summary MapStep(const WindowSnapshot& snapshot, const BackendOptions& options,
                               WindowState* state, int* blocks) {
  ceres::Problem problem;
  ceres::LossFunction* loss = MakeLoss(options);
  if (options.lane_residual == LaneResidual::kPsr) RefreshPsrPoints(snapshot, options, state);
  *blocks = AddMapStepMeasurements(snapshot, options,
                                   state->hold_out ? Measurements::kTraining : Measurements::kAll,
                                   loss, state, &problem);
  if (*blocks == 0) {
    delete loss;
    return ceres::Solver::Summary();
  }
  AddMapPointPriors(options, state, &problem);
  // The extrinsic, held also in the directions the data does not observe.
  if (AddExtrinsicPrior(snapshot, options, state, &problem) && options.extrinsic_hold_unobserved &&
      state->observability_valid) {
    HoldUnobservedDirections(state->observability, snapshot.T_base_cam, state, &problem);
  }
  return Solve(options, state->step_time_limit_s, &problem);
}

bool AddExtrinsicPrior(const WindowSnapshot& snapshot, const BackendOptions& options,
                       WindowState* state, ceres::Problem* problem) {
  double* q_bc = state->extrinsic.q;
  double* t_bc = state->extrinsic.t;
  if (!problem->HasParameterBlock(q_bc)) return false;
  problem->AddResidualBlock(residuals::ExtrinsicPriorResidual::Create(snapshot.extrinsic_prior),
                            nullptr, q_bc, t_bc);
  problem->SetManifold(q_bc, new ceres::EigenQuaternionManifold);
  if (!options.optimize_extrinsic || state->extrinsic_frozen) {
    problem->SetParameterBlockConstant(q_bc);
    problem->SetParameterBlockConstant(t_bc);
    return false;
  }
  return true;
}

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

}  // namespace window_solve
}  // namespace ipm_road_mapper
