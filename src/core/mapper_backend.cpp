// The Mapper's side of the back end: building a window snapshot, retiring the elements
// that leave the window into the extrinsic prior, and merging results into the map.
#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>

#include "ipm_road_mapper/core/extrinsic_marginalization.h"
#include "ipm_road_mapper/core/ipm.h"
#include "ipm_road_mapper/core/mapper.h"
#include "ipm_road_mapper/core/marking_measurement.h"
#include "ipm_road_mapper/core/residuals/corner_reprojection_residual.h"
#include "ipm_road_mapper/core/residuals/ground_height_prior_residual.h"

namespace ipm_road_mapper {
std::size_t Mapper::ClosestFrame(const Eigen::Vector3d& p_map) const {
  double best = std::numeric_limits<double>::infinity();
  std::size_t best_index = 0;
  for (const FrameRecord& f : map_.frames) {
    const double d = (f.T_map_base.translation() - p_map).head<2>().squaredNorm();
    if (d < best) {
      best = d;
      best_index = f.index;
    }
  }
  return best_index;
}

void Mapper::AddRoadPrior(int point, const Eigen::Vector3d& p_map,
                          MarginalizationInput* input) const {
  const FrameRecord& road = map_.frames[ClosestFrame(p_map)];
  const double distance = (road.T_map_base.translation() - p_map).head<2>().norm();
  const BackendOptions& o = options_.backend;
  input->road_priors.push_back(
      {point, road.T_map_base,
       std::hypot(o.road_height_sigma_m, o.road_height_sigma_per_m * distance)});
}

void Mapper::RetireMarking(MarkingElement* marking) {
  marking->retired = true;
  if (!options_.backend.optimize_extrinsic || !options_.backend.optimize_markings) return;
  const PinholeCamera camera(camera_);
  MarginalizationInput input;
  input.points.assign(marking->corners_map.begin(), marking->corners_map.end());
  // Corners re-measured on the road plane where the vehicle passed the marking.
  const FrameRecord& road = map_.frames[ClosestFrame(marking->Center())];
  const RoadPlane plane{road.T_map_base.translation(), road.T_map_base.linear().col(2)};
  const Eigen::Vector3d axis = RoadDirectionAt(marking->Center());
  for (const MarkingMeasurement& m : marking->history) {
    const Eigen::Isometry3d& T_map_base = map_.frames[m.frame_index].T_map_base;
    std::array<Eigen::Vector2d, 4> corners_uv = m.corners_uv;
    if (axis.norm() > 0.0 && !m.outline_uv.empty()) {
      std::array<Eigen::Vector2d, 4> on_plane;
      if (MeasureCornersOnPlane(camera, T_map_base * T_base_cam_, plane, axis, marking->corners_map,
                                m.outline_uv, &on_plane)) {
        corners_uv = on_plane;
      }
    }
    for (int c = 0; c < 4; ++c) input.corners.push_back({c, corners_uv[c], T_map_base});
  }
  if (options_.backend.optimize_z) {
    for (int c = 0; c < 4; ++c) AddRoadPrior(c, marking->corners_map[c], &input);
  }
  extrinsic_prior_.Add(MarginalizeIntoExtrinsic(camera, extrinsic_prior_, T_base_cam_, input,
                                                options_.backend.pixel_sigma_px,
                                                options_.backend.robust_scale));
}

namespace {

// Observations a marking needs (besides one solve) before it corrects poses.
constexpr std::size_t kMinMatureObservations = 5;

}  // namespace

void Mapper::RefineRetiredMarkings() {
  if (!options_.backend.optimize_markings) return;
  const PinholeCamera camera(camera_);
  const Eigen::Quaterniond q_bc(T_base_cam_.linear());
  double q_base_cam[4] = {q_bc.x(), q_bc.y(), q_bc.z(), q_bc.w()};
  double t_base_cam[3] = {T_base_cam_.translation().x(), T_base_cam_.translation().y(),
                          T_base_cam_.translation().z()};
  for (MarkingElement& marking : map_.markings) {
    if (!marking.retired || marking.history.size() < 2) continue;
    std::array<Eigen::Vector3d, 4> corners = marking.corners_map;
    ceres::Problem problem;
    const FrameRecord& road = map_.frames[ClosestFrame(marking.Center())];
    const RoadPlane plane{road.T_map_base.translation(), road.T_map_base.linear().col(2)};
    const Eigen::Vector3d axis = RoadDirectionAt(marking.Center());
    std::vector<std::array<double, 7>> poses;
    poses.reserve(marking.history.size());
    for (const MarkingMeasurement& m : marking.history) {
      const Eigen::Isometry3d& T_map_base = map_.frames[m.frame_index].T_map_base;
      std::array<Eigen::Vector2d, 4> corners_uv = m.corners_uv;
      std::array<Eigen::Vector2d, 4> on_plane;
      if (axis.norm() > 0.0 && !m.outline_uv.empty() &&
          MeasureCornersOnPlane(camera, T_map_base * T_base_cam_, plane, axis, corners,
                                m.outline_uv, &on_plane)) {
        corners_uv = on_plane;
      }
      const Eigen::Quaterniond q(T_map_base.linear());
      poses.push_back({q.x(), q.y(), q.z(), q.w(), T_map_base.translation().x(),
                       T_map_base.translation().y(), T_map_base.translation().z()});
      for (int c = 0; c < 4; ++c) {
        problem.AddResidualBlock(residuals::CornerReprojectionMapStepResidual::Create(
                                     camera, corners_uv[c], options_.backend.pixel_sigma_px,
                                     poses.back().data(), poses.back().data() + 4),
                                 new ceres::HuberLoss(options_.backend.robust_scale),
                                 corners[c].data(), q_base_cam, t_base_cam);
      }
    }
    problem.SetParameterBlockConstant(q_base_cam);
    problem.SetParameterBlockConstant(t_base_cam);
    const BackendOptions& o = options_.backend;
    for (int c = 0; c < 4; ++c) {
      if (!o.optimize_z) {
        problem.SetManifold(corners[c].data(), new ceres::SubsetManifold(3, {2}));
        continue;
      }
      const double distance = (road.T_map_base.translation() - corners[c]).head<2>().norm();
      problem.AddResidualBlock(
          residuals::GroundHeightPriorResidual::Create(
              road.T_map_base,
              std::hypot(o.road_height_sigma_m, o.road_height_sigma_per_m * distance)),
          nullptr, corners[c].data());
    }
    ceres::Solver::Options solver;
    solver.max_num_iterations = 10;
    solver.logging_type = ceres::SILENT;
    ceres::Solver::Summary summary;
    ceres::Solve(solver, &problem, &summary);
    if (summary.IsSolutionUsable()) marking.corners_map = corners;
  }
}

WindowSnapshot Mapper::BuildSnapshot() {
  const std::size_t window = static_cast<std::size_t>(options_.backend.window_frames);
  const std::size_t first = map_.frames.size() > window ? map_.frames.size() - window : 0;
  // Lanes keep the pixels of one more window of frames as context; older ones retire.
  const std::size_t lane_first = first > window ? first - window : 0;
  for (MarkingElement& m : map_.markings) {
    if (!m.retired && m.last_frame < first && m.optimized) RetireMarking(&m);
  }
  // Lane observations older than that leave the windows. Their information about the
  // extrinsic is not kept: marginalizing pixels of control points that later windows still
  // refine (a lane is never done, its control points are shared along it) made the prior
  // confidently wrong (0.5 deg of roll on the drive with odometry noise alone). The markings
  // carry the extrinsic's long-term information.
  for (LaneElement& l : map_.lanes)
    l.retired_before_frame = std::max(l.retired_before_frame, lane_first);

  WindowSnapshot snapshot;
  snapshot.sequence = next_sequence_++;
  snapshot.camera = camera_;
  snapshot.T_base_cam = T_base_cam_;
  snapshot.extrinsic_prior = extrinsic_prior_;
  std::set<std::size_t> context;  // frames of older measurements of the window's elements
  for (const MarkingElement& m : map_.markings) {
    if (m.last_frame < first) continue;  // outside the window: held fixed
    WindowMarking wm{m.id, m.corners_map, m.history, RoadDirectionAt(m.Center()),
                     m.optimized && m.history.size() >= kMinMatureObservations};
    for (const MarkingMeasurement& meas : m.history) {
      if (meas.frame_index < first) context.insert(meas.frame_index);
    }
    snapshot.markings.push_back(std::move(wm));
  }
  for (const LaneElement& l : map_.lanes) {
    if (l.last_frame < first) continue;
    WindowLane wl{l.id, l.first_cp_index, l.control_points_map, {}};
    for (const LaneMeasurement& meas : l.history) {
      if (meas.frame_index < std::max(lane_first, l.retired_before_frame)) continue;
      wl.measurements.push_back(meas);
      if (meas.frame_index < first) context.insert(meas.frame_index);
    }
    snapshot.lanes.push_back(std::move(wl));
  }
  for (std::size_t i : context) {
    const FrameRecord& f = map_.frames[i];
    snapshot.frames.push_back({f.index, f.T_map_base, f.T_map_base_odom, false});
  }
  for (std::size_t i = first; i < map_.frames.size(); ++i) {
    const FrameRecord& f = map_.frames[i];
    snapshot.frames.push_back({f.index, f.T_map_base, f.T_map_base_odom, true});
  }
  return snapshot;
}

void Mapper::ApplyBackendResults() {
  if (!backend_) return;
  for (const auto& result : backend_->TakeResults()) {
    if (!result->usable) {
      ++counters_.results_rejected;
      continue;
    }
    ApplyResult(*result);
    ++counters_.results_applied;
  }
}

void Mapper::ApplyResult(const WindowResult& result) {
  T_base_cam_ = result.T_base_cam;  // fed forward to the next frames' IPM
  for (const WindowFrame& f : result.frames) {
    if (f.in_window && f.index < map_.frames.size()) map_.frames[f.index].T_map_base = f.T_map_base;
  }
  if (options_.backend.optimize_markings) {
    for (const WindowMarking& wm : result.markings) {
      for (MarkingElement& m : map_.markings) {
        if (m.id != wm.id || m.retired) continue;
        m.corners_map = wm.corners_map;
        m.optimized = true;
      }
    }
  }
  if (!LanesRefinedByBackend()) return;
  for (const WindowLane& wl : result.lanes) {
    for (LaneElement& lane : map_.lanes) {
      if (lane.id != wl.id) continue;
      const std::int64_t offset = wl.first_cp_index - lane.first_cp_index;
      const std::int64_t n_result = static_cast<std::int64_t>(wl.control_points_map.size());
      const std::int64_t n_lane = static_cast<std::int64_t>(lane.control_points_map.size());
      for (std::int64_t j = 0; j < n_result; ++j) {
        const std::int64_t k = j + offset;
        if (k < 0 || k >= n_lane) continue;
        // A phantom end of the snapshot that has since become a real point: keep the new one.
        if ((j == 0 && k != 0) || (j == n_result - 1 && k != n_lane - 1)) continue;
        lane.control_points_map[k] = wl.control_points_map[j];
      }
      lane.optimized = true;
    }
  }
}

}  // namespace ipm_road_mapper
