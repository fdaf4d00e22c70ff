// Results back into the map: poses, the fed-forward extrinsic and what is known about it,
// the markings' corners and the lanes' control points.
#include <algorithm>
#include <unordered_map>
#include <vector>

#include "ipm_road_mapper/core/mapper/marking_extent.h"
#include "ipm_road_mapper/core/mapper/window_coordinator.h"

namespace ipm_road_mapper {

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
    counters_->joint_extrinsic_held += static_cast<std::uint64_t>(result.joint_extrinsic_held);
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
      MarkingElement& marking = *it->second;
      // A partial extent keeps its shape and its unmeasured sides (RectifyPartialExtent).
      marking.corners_map =
          marking.Complete()
              ? wm.corners_map
              : RectifyPartialExtent(marking.corners_map, wm.corners_map, marking.side_measured);
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
    store_->Touch(&lane, static_cast<std::size_t>(std::max<std::int64_t>(0, offset)));
  }
}

}  // namespace ipm_road_mapper
