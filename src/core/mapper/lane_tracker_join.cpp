// The lane tracker's joins of a line's fragments (lane_join.h), and at the end of the drive
// across a gap no frame saw (lane_gap_visibility.h, lane_path_bridge.h).
#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>

#include "ipm_road_mapper/core/frontend/association.h"
#include "ipm_road_mapper/core/mapper/change_log.h"
#include "ipm_road_mapper/core/mapper/lane_join.h"
#include "ipm_road_mapper/core/mapper/lane_tracker.h"

namespace ipm_road_mapper {

void LaneTracker::JoinFragments(std::size_t settled_before_frame) {
  const LaneJoinOptions& join = options_.lanes.join;
  if (!join.enabled) return;
  // The best pair first, until none passes: each end continues into at most one lane.
  // Online the lanes near the vehicle (LanesThatMayHaveChanged), at the end of the drive all.
  const bool online = settled_before_frame != std::numeric_limits<std::size_t>::max();
  // Ends farther apart than this cannot be joined (a cheap test before the models); a hidden
  // gap (JoinCost) is joined at the end of the drive only.
  const double max_gap_m =
      online ? join.max_gap_m : std::max(join.max_gap_m, join.max_hidden_gap_m);
  const double reach_m = max_gap_m + join.max_overlap_m + 2.0 * join.end_length_m;
  std::vector<LaneElement>& lanes = store_->lanes();
  while (true) {
    std::vector<std::size_t> among;
    if (online) {
      among = LanesThatMayHaveChanged();
    } else {
      among.resize(lanes.size());
      for (std::size_t i = 0; i < among.size(); ++i) among[i] = i;
    }
    double best_cost = -1.0;
    std::size_t best_a = 0, best_b = 0;
    std::optional<PathBridge> best_bridge;  // the best pair's, when hidden
    for (std::size_t a : among) {
      for (std::size_t b : among) {
        if (a == b || lanes[a].class_id != lanes[b].class_id) continue;
        // The junction's data (first's end, second's start) must have left the windows.
        if (std::max(lanes[a].last_frame, lanes[b].first_frame) >= settled_before_frame) continue;
        const auto& ca = lanes[a].control_points_map;
        const auto& cb = lanes[b].control_points_map;
        if (ca.size() < 4 || cb.size() < 4 ||
            (ca[ca.size() - 2] - cb[1]).head<2>().norm() > reach_m) {
          continue;
        }
        std::optional<PathBridge> bridge;
        const double cost = JoinCost(lanes[a], lanes[b], !online, &bridge);
        if (cost >= 0.0 && (best_cost < 0.0 || cost < best_cost)) {
          best_cost = cost;
          best_a = a;
          best_b = b;
          best_bridge = std::move(bridge);
        }
      }
    }
    if (best_cost < 0.0) return;
    std::optional<LaneElement> result;
    const bool hidden = best_bridge.has_value();
    if (hidden) {
      result = JoinLanesThrough(lanes[best_a], lanes[best_b], best_bridge->points,
                                best_bridge->first_end_dropped, best_bridge->second_start_dropped);
    } else {
      result = JoinLanes(lanes[best_a], lanes[best_b], join, options_.association,
                         options_.lanes.fit.chord_spacing_m);
    }
    if (!result) return;  // degenerate: left apart (rare; the next merge tries again)
    const auto changed_from =
        FirstChangedControlPoint(lanes[best_a].control_points_map, result->control_points_map);
    lanes[best_a] = std::move(*result);
    store_->Touch(&lanes[best_a], changed_from);
    lanes.erase(lanes.begin() + best_b);
    ++counters_->lanes_joined;
    if (hidden) ++counters_->lanes_joined_hidden_gap;
  }
}

void LaneTracker::SetCamera(const CameraIntrinsics& camera, const Eigen::Isometry3d& T_base_cam) {
  gap_camera_.camera = PinholeCamera(camera);
  gap_camera_.T_base_cam = T_base_cam;
  gap_camera_.error_model = options_.ipm.error_model;
}

double LaneTracker::JoinCost(const LaneElement& first, const LaneElement& second, bool at_end,
                             std::optional<PathBridge>* hidden_bridge) const {
  hidden_bridge->reset();
  const LaneJoinOptions& join = options_.lanes.join;
  bool co_observed = false;
  const double cost = LaneJoinCost(first, second, join, options_.association, &co_observed);
  if (cost >= 0.0 || !at_end || join.max_hidden_gap_m <= 0.0 || first.class_id != second.class_id ||
      co_observed) {
    return cost;
  }
  // A gap the ordinary join does not bridge: along the driven path, if no frame saw it.
  const FrameSpan span = GapSpan(first, second);
  std::optional<PathBridge> bridge = HiddenGapBridge(first, second, span);
  if (!bridge) return -1.0;
  // The two ends' offsets from the path agree within their combined floor sigma.
  const double sigma = std::sqrt(2.0) * LaneFloorSigma(options_.association);
  const double path_cost = std::abs(bridge->offset_change_m) / sigma;
  if (path_cost > join.gate_sigmas) return -1.0;
  GapViewOptions view;
  view.max_point_score_m2 = options_.association.lane_max_point_score_m2;
  view.max_range_m = options_.ipm.max_range_m;
  view.border_margin_px = options_.extraction.border_margin_px;
  view.min_seen_length_m = options_.lanes.min_new_lane_length_m;
  // The bridge lies between the two ends' offsets, each known to about the floor sigma.
  view.lateral_uncertainty_m = sigma + 0.5 * std::abs(bridge->offset_change_m);
  if (FramesThatSawGap(bridge->unseen_points, store_->frames(), span, gap_camera_, view) > 0) {
    return -1.0;
  }
  *hidden_bridge = std::move(bridge);
  return path_cost;
}

FrameSpan LaneTracker::GapSpan(const LaneElement& first, const LaneElement& second) const {
  return GapFrameSpan(store_->frames(), first.last_frame, second.first_frame,
                      options_.ipm.max_range_m);
}

std::optional<PathBridge> LaneTracker::HiddenGapBridge(const LaneElement& first,
                                                       const LaneElement& second,
                                                       const FrameSpan& span) const {
  const double spacing_m = options_.lanes.fit.chord_spacing_m;
  return BridgeAlongPath(first, second, store_->frames(), span,
                         options_.lanes.join.max_hidden_gap_m, spacing_m, spacing_m,
                         options_.lanes.join.end_length_m,
                         options_.lanes.join.gate_sigmas * LaneFloorSigma(options_.association));
}

}  // namespace ipm_road_mapper
