#include "ipm_road_mapper/core/mapper/window_coordinator.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iterator>
#include <set>
#include <unordered_map>

#include "ipm_road_mapper/core/backend/extrinsic_marginalization.h"
#include "ipm_road_mapper/core/frontend/marking_measurement.h"
#include "ipm_road_mapper/core/geometry/catmull_rom_spline.h"

namespace ipm_road_mapper {
namespace {

// A marking enters the back end once it has been seen from this close: seen only from
// 15-20 m, with the odometry's 0.1 m of noise on the baseline, its triangulated depth is off
// by meters (4.5 m observed), worse than the front end's IPM average, and the association
// then starts a duplicate. It corrects poses after one solve and this many observations.
constexpr double kMatureRangeM = 15.0;
constexpr std::size_t kMinMatureObservations = 5;

// Whether the marking has been seen from within kMatureRangeM of base_link.
bool SeenUpClose(const MarkingElement& m) {
  for (const MarkingMeasurement& meas : m.history) {
    const Eigen::Vector3d center = 0.25 * (meas.corners_base[0] + meas.corners_base[1] +
                                           meas.corners_base[2] + meas.corners_base[3]);
    if (center.head<2>().norm() <= kMatureRangeM) return true;
  }
  return false;
}

// The part of a lane a window needs: the control points near its measurements' points (at
// the frames' current poses), with a margin of two chords and the pixel gate, plus two more
// on each side, so that every segment a pixel can fall on, and every smoothness triple
// touching a point that can move, lies inside. A lane can be kilometers long; a window
// looks at tens of meters of it. Writes the part and its global index of the first point.
void SliceForWindow(const LaneElement& lane, const std::vector<const LaneMeasurement*>& window,
                    const std::vector<FrameRecord>& frames, double margin_m, WindowLane* out) {
  std::vector<Eigen::Vector3d> points_map;
  for (const LaneMeasurement* m : window) {
    const Eigen::Isometry3d& T_map_base = frames[m->frame_index].T_map_base;
    for (std::size_t i = 0; i < m->points.size(); ++i) {
      if (m->selected[i]) points_map.push_back(T_map_base * m->points[i].p_base);
    }
  }
  const std::vector<Eigen::Vector3d>& cps = lane.control_points_map;
  std::size_t first = 0, last = cps.empty() ? 0 : cps.size() - 1;
  if (ControlPointRangeNear(cps, points_map, margin_m, &first, &last)) {
    first = first >= 2 ? first - 2 : 0;
    last = std::min(cps.size() - 1, last + 2);
  } else {
    first = 0;
    last = cps.empty() ? 0 : cps.size() - 1;
  }
  out->first_cp_index = lane.first_cp_index + static_cast<std::int64_t>(first);
  out->control_points_map.assign(cps.begin() + first,
                                 cps.empty() ? cps.end() : cps.begin() + last + 1);
}

}  // namespace

std::size_t LaneContextStart(const BackendOptions& options, std::size_t frame_count) {
  const std::size_t window = static_cast<std::size_t>(options.window_frames);
  const std::size_t first = frame_count > window ? frame_count - window : 0;
  return first > window ? first - window : 0;
}

WindowCoordinator::WindowCoordinator(const MapperOptions& options,
                                     const Eigen::Isometry3d& T_base_cam_initial, MapStore* store,
                                     MapperCounters* counters)
    : options_(options),
      T_base_cam_initial_(T_base_cam_initial),
      T_base_cam_(T_base_cam_initial),
      store_(store),
      counters_(counters),
      extrinsic_prior_(T_base_cam_initial, options.backend.rotation_prior_sigma_rad,
                       options.backend.translation_prior_sigma_m,
                       options.backend.extrinsic_prior_memory_markings) {
  extrinsic_covariance_ = extrinsic_prior_.H().inverse();
  if (options_.backend.enabled) backend_ = std::make_unique<Backend>(options_.backend);
}

WindowCoordinator::~WindowCoordinator() {
  if (backend_) backend_->Stop();
}

bool WindowCoordinator::LanesRefined() const {
  return backend_ && options_.backend.lane_residual != LaneResidual::kNone;
}

BackendStats WindowCoordinator::stats() const {
  return backend_ ? backend_->stats() : BackendStats();
}

PoseCovariance WindowCoordinator::PoseCovarianceOf(std::size_t index) const {
  const BackendOptions& o = options_.backend;
  const Eigen::Isometry3d T_map_base = store_->CorrectedPose(index);
  const PoseCovariance odometry =
      OdometryPoseCovariance(T_map_base, o.pose_prior_sigma_trans_m, o.pose_prior_sigma_rot_rad);
  if (pose_covariance_frame_ < 0 || static_cast<std::size_t>(pose_covariance_frame_) > index)
    return odometry;
  const std::size_t solved = static_cast<std::size_t>(pose_covariance_frame_);
  return PropagatePoseCovariance(pose_covariance_, store_->frames()[solved].T_map_base, T_map_base,
                                 solved == index ? PoseCovariance::Zero() : odometry);
}

void WindowCoordinator::Reset() {
  pose_covariance_frame_ = -1;
  if (!backend_) return;
  backend_->Stop();  // results of the old map must not land in the new one
  backend_ = std::make_unique<Backend>(options_.backend);
}

void WindowCoordinator::OnFrameUsed(std::uint64_t frames_used, const CameraIntrinsics& camera) {
  camera_ = camera;
  if (frames_used % options_.backend.solve_every_n_frames != 0) return;
  if (backend_) {
    backend_->Submit(BuildSnapshot());
    return;
  }
  // Without a back end the markings that leave the window retire all the same, so that the
  // front end's per-frame work stays with the live ones.
  const std::size_t first = WindowStart();
  for (MarkingElement& m : store_->markings()) {
    if (m.last_frame < first) m.retired = true;
  }
  store_->RetireMarkings(first);
}

std::size_t WindowCoordinator::WindowStart() const {
  const std::size_t window = static_cast<std::size_t>(options_.backend.window_frames);
  const std::size_t frames = store_->frames().size();
  return frames > window ? frames - window : 0;
}

bool WindowCoordinator::Finish(double time_budget_s) {
  if (!backend_ || store_->frames().empty()) return true;
  const auto start = std::chrono::steady_clock::now();
  auto remaining_s = [&] {
    return time_budget_s -
           std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  backend_->Submit(BuildSnapshot());
  if (!backend_->WaitIdleFor(remaining_s())) return false;  // its result comes later, if ever
  ApplyResults();
  FinalGlobalSolve(remaining_s());
  return remaining_s() >= 0.0;
}

double WindowCoordinator::RoadPriorSigma(const RoadSurfaceEstimate& road) const {
  const BackendOptions& o = options_.backend;
  return std::hypot(o.road_height_sigma_m, o.road_height_sigma_per_m * road.distance_m);
}

void WindowCoordinator::RetireMarking(MarkingElement* marking) {
  marking->retired = true;
  if (!options_.backend.optimize_extrinsic || !options_.backend.optimize_markings) return;
  const PinholeCamera camera(camera_);
  MarginalizationInput input;
  input.points.assign(marking->corners_map.begin(), marking->corners_map.end());
  // Corners re-measured on the road plane where the vehicle passed the marking.
  const RoadSurfaceEstimate road = store_->RoadSurfaceAt(marking->Center());
  const RoadPlane& plane = road.plane;
  const Eigen::Vector3d axis = store_->RoadDirectionAt(marking->Center());
  // As in the window problem: partial views only for a marking no whole view shows.
  const bool seen_whole = std::any_of(marking->history.begin(), marking->history.end(),
                                      [](const MarkingMeasurement& m) { return m.Complete(); });
  for (const MarkingMeasurement& m : marking->history) {
    if (seen_whole && !m.Complete()) continue;
    const Eigen::Isometry3d& T_map_base = store_->frames()[m.frame_index].T_map_base;
    std::array<Eigen::Vector2d, 4> corners_uv = m.corners_uv;
    if (axis.norm() > 0.0 && !m.outline_uv.empty()) {
      std::array<Eigen::Vector2d, 4> on_plane;
      if (MeasureCornersOnPlane(camera, T_map_base * T_base_cam_, plane, axis, marking->corners_map,
                                m.outline_uv, &on_plane)) {
        corners_uv = on_plane;
      }
    }
    for (int c = 0; c < 4; ++c) {
      // Only corners the view measured (a partial view's cut corners are where it ended).
      if (!m.CornerMeasured(c) || !corners_uv[c].allFinite()) continue;
      input.corners.push_back({c, corners_uv[c], T_map_base});
    }
  }
  if (options_.backend.optimize_z) {
    for (int c = 0; c < 4; ++c) {
      const RoadSurfaceEstimate at = store_->RoadSurfaceAt(marking->corners_map[c]);
      input.road_priors.push_back({c, at.plane, RoadPriorSigma(at)});
    }
  }
  extrinsic_prior_.Add(MarginalizeIntoExtrinsic(camera, extrinsic_prior_, T_base_cam_, input,
                                                options_.backend.pixel_sigma_px,
                                                options_.backend.robust_scale));
}

void WindowCoordinator::FinalGlobalSolve(double time_budget_s) {
  const BackendOptions& o = options_.backend;
  const std::vector<FrameRecord>& frames = store_->frames();
  if (!o.final_global_solve || frames.empty()) return;
  // Everything at once over the last final_global_max_frames frames (all of a shorter
  // drive): those frames free, every marking that reached the back end and every lane with
  // their observations in that span, the extrinsic with the mounting prior alone (all the
  // data it summarizes is in the problem itself, for a drive within the span). Older frames
  // keep what the windows made of them: the solve's cost and memory are bounded by the span.
  const std::size_t span = static_cast<std::size_t>(o.final_global_max_frames);
  const std::size_t start = frames.size() > span ? frames.size() - span : 0;
  WindowSnapshot snapshot;
  snapshot.sequence = next_sequence_++;
  snapshot.camera = camera_;
  snapshot.T_base_cam = T_base_cam_;
  snapshot.extrinsic_prior =
      ExtrinsicPrior(T_base_cam_initial_, o.rotation_prior_sigma_rad, o.translation_prior_sigma_m);
  snapshot.newest_pose_covariance = false;  // the windows' covariance stands
  // The drive's calibration: cross-validated, never moved where the data cannot confirm it.
  snapshot.cross_validate_extrinsic = true;
  auto in_span = [start](const auto& measurement) { return measurement.frame_index >= start; };
  std::vector<const MarkingElement*> markings;
  for (const MarkingElement& m : store_->markings()) markings.push_back(&m);
  for (const MarkingElement& m : store_->retired_markings()) markings.push_back(&m);
  for (const MarkingElement* marking : markings) {
    const MarkingElement& m = *marking;
    if (!m.optimized || m.last_frame < start) continue;
    const bool partial_only = !m.Complete() || std::none_of(m.history.begin(), m.history.end(),
                                                            [](const MarkingMeasurement& meas) {
                                                              return meas.Complete();
                                                            });
    WindowMarking wm{m.id,
                     m.corners_map,
                     {},
                     store_->RoadDirectionAt(m.Center()),
                     !partial_only && m.Observations() >= kMinMatureObservations,
                     partial_only};
    std::copy_if(m.history.begin(), m.history.end(), std::back_inserter(wm.measurements), in_span);
    snapshot.markings.push_back(std::move(wm));
  }
  const double margin_m = 2.0 * options_.lanes.fit.chord_spacing_m + o.max_lane_pixel_distance_m;
  for (const LaneElement& l : store_->lanes()) {
    if (l.last_frame < start) continue;
    std::vector<const LaneMeasurement*> span_measurements;
    for (const LaneMeasurement& m : l.history) {
      if (in_span(m)) span_measurements.push_back(&m);
    }
    WindowLane wl{l.id, l.first_cp_index, l.control_points_map, {}};
    if (start > 0) SliceForWindow(l, span_measurements, frames, margin_m, &wl);
    for (const LaneMeasurement* m : span_measurements) wl.measurements.push_back(*m);
    snapshot.lanes.push_back(std::move(wl));
  }
  for (std::size_t i = start; i < frames.size(); ++i) {
    const FrameRecord& f = frames[i];
    snapshot.frames.push_back({f.index, f.T_map_base, f.T_map_base_odom, true, f.stamp});
  }
  BackendOptions global = o;
  global.rounds = o.final_global_rounds;
  global.max_measurements_per_marking =
      std::max(o.max_measurements_per_marking, o.final_global_min_measurements_per_marking);
  global.max_extrinsic_change_rad = 1e9;  // the trust bound guards windows, not this
  global.max_extrinsic_change_m = 1e9;
  if (!(time_budget_s > 0.0)) return;
  const WindowResult result = SolveWindow(snapshot, global, time_budget_s);
  if (!result.usable) {
    ++counters_->results_rejected;
    return;
  }
  ApplyResult(result, /*include_retired=*/true);
  store_->ReindexRetiredMarkings();  // their corners moved
  ++counters_->results_applied;
}

WindowSnapshot WindowCoordinator::BuildSnapshot() {
  const std::vector<FrameRecord>& frames = store_->frames();
  const std::size_t first = WindowStart();
  // Lanes keep the pixels of one more window of frames as context; older ones retire.
  const std::size_t lane_first = LaneContextStart(options_.backend, frames.size());
  for (MarkingElement& m : store_->markings()) {
    if (!m.retired && m.last_frame < first && m.optimized) RetireMarking(&m);
    if (!m.retired && m.last_frame < first) m.retired = true;  // never reached the back end
  }
  store_->RetireMarkings(first);
  // Lane observations older than that leave the windows. Their information about the
  // extrinsic is not kept: marginalizing pixels of control points that later windows still
  // refine (a lane is never done, its control points are shared along it) made the prior
  // confidently wrong (0.5 deg of roll on the drive with odometry noise alone). The markings
  // carry the extrinsic's long-term information.
  for (LaneElement& l : store_->lanes()) {
    l.retired_before_frame = std::max(l.retired_before_frame, lane_first);
  }

  WindowSnapshot snapshot;
  snapshot.sequence = next_sequence_++;
  snapshot.camera = camera_;
  snapshot.T_base_cam = T_base_cam_;
  snapshot.extrinsic_prior = extrinsic_prior_;
  std::set<std::size_t> context;  // frames of older measurements of the window's elements
  for (const MarkingElement& m : store_->markings()) {
    if (m.last_frame < first) continue;  // outside the window: held fixed
    if (!SeenUpClose(m)) continue;       // the front end's estimate until it is
    if (!m.confirmed) continue;          // tentative (maybe a spurious blob): no pull
    // Seen only in partial views (larger than the view): refined with the extrinsic held,
    // never correcting poses (on av2_pit_dev such crossings pulled the roll by 0.8 deg).
    const bool partial_only =
        std::none_of(m.history.begin(), m.history.end(),
                     [](const MarkingMeasurement& meas) { return meas.Complete(); });
    WindowMarking wm{m.id,
                     m.corners_map,
                     m.history,
                     store_->RoadDirectionAt(m.Center()),
                     !partial_only && m.optimized && m.Observations() >= kMinMatureObservations,
                     partial_only};
    for (const MarkingMeasurement& meas : m.history) {
      if (meas.frame_index < first) context.insert(meas.frame_index);
    }
    snapshot.markings.push_back(std::move(wm));
  }
  const double margin_m =
      2.0 * options_.lanes.fit.chord_spacing_m + options_.backend.max_lane_pixel_distance_m;
  for (const LaneElement& l : store_->lanes()) {
    if (l.last_frame < first) continue;
    // The history is sorted by frame: the window's part is its tail.
    const std::size_t from = std::max(lane_first, l.retired_before_frame);
    auto begin =
        std::lower_bound(l.history.begin(), l.history.end(), from,
                         [](const LaneMeasurement& m, std::size_t f) { return m.frame_index < f; });
    std::vector<const LaneMeasurement*> window;
    for (auto it = begin; it != l.history.end(); ++it) window.push_back(&*it);
    WindowLane wl{l.id, 0, {}, {}};
    SliceForWindow(l, window, frames, margin_m, &wl);
    for (const LaneMeasurement* meas : window) {
      wl.measurements.push_back(*meas);
      if (meas->frame_index < first) context.insert(meas->frame_index);
    }
    snapshot.lanes.push_back(std::move(wl));
  }
  for (std::size_t i : context) {
    const FrameRecord& f = frames[i];
    snapshot.frames.push_back({f.index, f.T_map_base, f.T_map_base_odom, false, f.stamp});
  }
  for (std::size_t i = first; i < frames.size(); ++i) {
    const FrameRecord& f = frames[i];
    snapshot.frames.push_back({f.index, f.T_map_base, f.T_map_base_odom, true, f.stamp});
  }
  return snapshot;
}

void WindowCoordinator::ApplyResults() {
  if (!backend_) return;
  for (const auto& result : backend_->TakeResults()) {
    if (!result->usable) {
      ++counters_->results_rejected;
      continue;
    }
    ApplyResult(*result, false);
    ++counters_->results_applied;
  }
}

void WindowCoordinator::ApplyResult(const WindowResult& result, bool include_retired) {
  T_base_cam_ = result.T_base_cam;  // fed forward to the next frames' IPM
  if (result.extrinsic_rejected) {
    ++counters_->extrinsic_rejected;  // T_base_cam is the previous one; so is what is known
  } else {
    counters_->extrinsic_rejected += result.extrinsic_directions_reverted > 0 ? 1 : 0;
    extrinsic_covariance_ = result.T_base_cam_covariance;
    for (int i = 0; i < 6; ++i) observed_[i] = observed_[i] || result.extrinsic_observed[i];
  }
  // The poses the pose step moved; the others are the snapshot's and may since have been
  // corrected by a newer result.
  std::vector<std::size_t> optimized;
  for (const WindowFrame& f : result.frames) {
    if (f.in_window && f.optimized && f.index < store_->frames().size()) {
      store_->SetFramePose(f.index, f.T_map_base);
      optimized.push_back(f.index);
    }
  }
  // The correction fitted over the moved frames, carried along the odometry to the frames
  // after them in the outputs (MapStore::CorrectedPose; the estimator keeps the raw odometry
  // as their start and prior: the correction is never a measurement).
  store_->SetCorrectionFrom(optimized);
  if (result.covariance_frame >= 0 &&
      static_cast<std::size_t>(result.covariance_frame) < store_->frames().size()) {
    pose_covariance_frame_ = result.covariance_frame;
    pose_covariance_ = result.T_map_base_covariance;
  }
  if (options_.backend.optimize_markings) {
    std::unordered_map<std::uint64_t, MarkingElement*> by_id;
    for (MarkingElement& m : store_->markings()) by_id.emplace(m.id, &m);
    if (include_retired) {
      for (MarkingElement& m : store_->retired_markings()) by_id.emplace(m.id, &m);
    }
    for (const WindowMarking& wm : result.markings) {
      auto it = by_id.find(wm.id);
      if (it == by_id.end() || (it->second->retired && !include_retired)) continue;
      it->second->corners_map = wm.corners_map;
      it->second->optimized = true;
      store_->Touch(it->second);
    }
  }
  if (!LanesRefined()) return;
  std::unordered_map<std::uint64_t, LaneElement*> by_id;
  for (LaneElement& lane : store_->lanes()) by_id.emplace(lane.id, &lane);
  for (const WindowLane& wl : result.lanes) {
    auto it = by_id.find(wl.id);
    if (it == by_id.end()) continue;
    LaneElement& lane = *it->second;
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
    store_->Touch(&lane);
  }
}

}  // namespace ipm_road_mapper
