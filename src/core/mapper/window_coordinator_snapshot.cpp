// What the back end solves: the window snapshot every backend.solve_every_n_frames frames
// (after retiring what left the window) and the final global solve's snapshot.
#include <algorithm>
#include <iterator>
#include <set>

#include "ipm_road_mapper/core/mapper/marking_maturity.h"
#include "ipm_road_mapper/core/mapper/window_coordinator.h"
#include "ipm_road_mapper/core/mapper/window_lane_slice.h"

namespace ipm_road_mapper {

void WindowCoordinator::FinalGlobalSolve(double time_budget_s) {
  const BackendOptions& o = options_.backend;
  if (!o.final_global_solve || store_->frames().empty()) return;
  if (!(time_budget_s > 0.0)) return;
  BackendOptions global = o;
  global.rounds = o.final_global_rounds;
  global.max_measurements_per_marking =
      std::max(o.max_measurements_per_marking, o.final_global_min_measurements_per_marking);
  global.max_extrinsic_change_rad = 1e9;  // the trust bound guards windows, not this
  global.max_extrinsic_change_m = 1e9;
  const WindowResult result = SolveWindow(BuildGlobalSnapshot(), global, time_budget_s);
  if (!result.usable) {
    ++counters_->results_rejected;
    return;
  }
  ApplyResult(result, /*include_retired=*/true);
  store_->ReindexRetiredMarkings();  // their corners moved
  ++counters_->results_applied;
}

WindowSnapshot WindowCoordinator::BuildGlobalSnapshot() {
  const BackendOptions& o = options_.backend;
  const std::vector<FrameRecord>& frames = store_->frames();
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
  // The batch estimate starts at its prior's center: where the windows left the extrinsic
  // depends on their path (which window result came when), and a solve from there stays in
  // that path's valley (docs/backend.md, "Where the global solve starts").
  snapshot.T_base_cam = o.final_global_from_mounting ? T_base_cam_initial_ : T_base_cam_;
  snapshot.extrinsic_prior =
      ExtrinsicPrior(T_base_cam_initial_, o.rotation_prior_sigma_rad, o.translation_prior_sigma_m);
  snapshot.newest_pose_covariance = false;  // the windows' covariance stands
  // The drive's calibration: cross-validated, never moved where the data cannot confirm it.
  snapshot.cross_validate_extrinsic = true;
  snapshot.joint_step_iterations = o.final_global_joint_iterations;
  auto in_span = [start](const auto& measurement) { return measurement.frame_index >= start; };
  std::vector<const MarkingElement*> markings;
  for (const MarkingElement& m : store_->markings()) markings.push_back(&m);
  for (const MarkingElement& m : store_->retired_markings()) markings.push_back(&m);
  for (const MarkingElement* marking : markings) {
    const MarkingElement& m = *marking;
    if (!m.optimized || m.last_frame < start) continue;
    const bool partial_only = !m.Complete() || SeenOnlyInPartialViews(m);
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
    snapshot.frames.push_back(
        {f.index, f.T_map_base, f.T_map_base_odom, true, f.stamp, false, f.ground_base});
  }
  return snapshot;
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
    const bool partial_only = SeenOnlyInPartialViews(m);
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
    snapshot.frames.push_back(
        {f.index, f.T_map_base, f.T_map_base_odom, false, f.stamp, false, f.ground_base});
  }
  for (std::size_t i = first; i < frames.size(); ++i) {
    const FrameRecord& f = frames[i];
    snapshot.frames.push_back(
        {f.index, f.T_map_base, f.T_map_base_odom, true, f.stamp, false, f.ground_base});
  }
  return snapshot;
}

}  // namespace ipm_road_mapper
