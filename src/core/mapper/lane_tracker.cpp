#include "ipm_road_mapper/core/mapper/lane_tracker.h"

#include <algorithm>
#include <cmath>

#include "ipm_road_mapper/core/frontend/association.h"
#include "ipm_road_mapper/core/geometry/ipm.h"
#include "ipm_road_mapper/core/geometry/lane_end_fit.h"
#include "ipm_road_mapper/core/geometry/spline_fitting.h"
#include "ipm_road_mapper/core/mapper/lane_join.h"
#include "ipm_road_mapper/core/mapper/path_curvature.h"
#include "ipm_road_mapper/core/mapper/window_coordinator.h"

namespace ipm_road_mapper {
namespace {

// The radius about `center` of a disc that holds every point within the association's
// reach of the candidates' points: LaneAssociationCost looks only at the control points in
// the points' bounding box grown by `margin_m` (ControlPointRangeNear), so the farthest
// corner of that box bounds it.
double CandidateReach(const std::vector<LaneCandidate>& candidates, const Eigen::Vector3d& center,
                      double margin_m) {
  bool any = false;
  Eigen::Vector2d lo = Eigen::Vector2d::Zero(), hi = lo;
  for (const LaneCandidate& c : candidates) {
    for (const Eigen::Vector3d& p : c.points_map) {
      if (!p.allFinite()) continue;
      lo = any ? lo.cwiseMin(p.head<2>()).eval() : p.head<2>();
      hi = any ? hi.cwiseMax(p.head<2>()).eval() : p.head<2>();
      any = true;
    }
  }
  if (!any) return 0.0;
  lo.array() -= margin_m;
  hi.array() += margin_m;
  const Eigen::Vector2d c = center.head<2>();
  const Eigen::Vector2d far((c.x() - lo.x() > hi.x() - c.x()) ? lo.x() : hi.x(),
                            (c.y() - lo.y() > hi.y() - c.y()) ? lo.y() : hi.y());
  return (far - c).norm();
}

// Point selection (PS): flags of the points kept for control-point estimation.
std::vector<std::uint8_t> SelectPoints(const std::vector<LanePoint>& points,
                                       const LaneOptions& options) {
  std::vector<std::uint8_t> selected(points.size(), options.point_selection ? 0 : 1);
  if (!options.point_selection) return selected;
  std::vector<double> scores;
  scores.reserve(points.size());
  for (const LanePoint& p : points) {
    scores.push_back(p.score <= options.max_selected_score_m2 ? p.score : std::nan(""));
  }
  for (std::size_t i : SelectLowestScores(scores, options.selected_points_per_frame)) {
    selected[i] = 1;
  }
  return selected;
}

// Largest horizontal distance of a point from the first one.
double Extent(const std::vector<Eigen::Vector3d>& points) {
  double extent = 0.0;
  for (std::size_t i = 1; i < points.size(); ++i) {
    extent = std::max(extent, (points[i] - points.front()).head<2>().norm());
  }
  return extent;
}

// The candidate's points usable for association and growth.
std::vector<Eigen::Vector3d> UsablePoints(const LaneCandidate& candidate) {
  std::vector<Eigen::Vector3d> usable_map;
  for (std::size_t i = 0; i < candidate.points_map.size(); ++i) {
    if (candidate.usable[i]) usable_map.push_back(candidate.points_map[i]);
  }
  return usable_map;
}

// A lane as an association candidate for the merge: its real control points (ordered along
// it), only the ones LaneAssociationCost would look at (it spreads about 12 over a
// candidate), so that a pair's test does not copy two lanes kilometers long.
LaneCandidate SampledCandidate(const LaneElement& lane) {
  constexpr std::size_t kSamples = 12;
  LaneCandidate candidate;
  candidate.class_id = lane.class_id;
  const std::vector<Eigen::Vector3d>& cps = lane.control_points_map;
  if (cps.size() < 3) return candidate;
  const std::size_t n = cps.size() - 2;  // phantom ends out
  const std::size_t step = std::max<std::size_t>(1, n / kSamples);
  for (std::size_t i = 0; i < n; i += step) candidate.points_map.push_back(cps[1 + i]);
  return candidate;
}

}  // namespace

LaneTracker::LaneTracker(const MapperOptions& options, MapStore* store, MapperCounters* counters)
    : options_(options), store_(store), counters_(counters) {}

LaneTracker::FrameAssociation LaneTracker::Associate(
    const std::vector<LaneObservation>& observations, const FrameRecord& frame) const {
  FrameAssociation a;
  const Eigen::Matrix2d R = frame.T_map_base.linear().topLeftCorner<2, 2>();
  for (const LaneObservation& obs : observations) {
    LaneCandidate candidate;
    candidate.class_id = obs.class_id;
    LaneMeasurement measurement;
    measurement.frame_index = frame.index;
    measurement.points = obs.points;
    measurement.selected = SelectPoints(obs.points, options_.lanes);
    for (std::size_t i = 0; i < obs.points.size(); ++i) {
      const Eigen::Vector3d p_map = frame.T_map_base * obs.points[i].p_base;
      candidate.points_map.push_back(p_map);
      candidate.cov_map.push_back(R * obs.points[i].cov_base * R.transpose());
      candidate.usable.push_back(obs.points[i].score <=
                                 options_.association.lane_max_point_score_m2);
      if (measurement.selected[i]) measurement.selected_map.push_back(p_map);
    }
    a.candidates.push_back(std::move(candidate));
    a.measurements.push_back(std::move(measurement));
  }
  // Only the lanes within the candidates' reach (a neighbourhood, not the drive's lanes).
  a.near = store_->LanesNear(
      frame.T_map_base.translation(),
      CandidateReach(a.candidates, frame.T_map_base.translation(), AssociationMarginM()));
  a.match = AssociateLanes(store_->lanes(), a.near, a.candidates, options_.association);
  return a;
}

std::optional<double> LaneTracker::OffsetAcross(const FrameAssociation& association,
                                                const FrameRecord& frame) const {
  const std::vector<LaneElement>& lanes = store_->lanes();
  const Eigen::Vector2d left = frame.T_map_base.linear().col(1).head<2>().normalized();
  std::vector<double> offsets;
  for (std::size_t c = 0; c < association.candidates.size(); ++c) {
    if (association.match[c] < 0) continue;
    const double offset =
        LaneOffsetAcross(lanes[association.match[c]], association.candidates[c], left);
    if (std::isfinite(offset)) offsets.push_back(offset);
  }
  if (offsets.empty()) return std::nullopt;
  const std::size_t mid = offsets.size() / 2;
  std::nth_element(offsets.begin(), offsets.begin() + mid, offsets.end());
  return offsets[mid];
}

void LaneTracker::Update(const std::vector<LaneObservation>& observations,
                         const FrameRecord& frame) {
  Update(Associate(observations, frame), frame);
}

void LaneTracker::Update(FrameAssociation association, const FrameRecord& frame) {
  std::vector<LaneCandidate>& candidates = association.candidates;
  std::vector<LaneMeasurement>& measurements = association.measurements;
  const std::vector<int>& match = association.match;
  std::vector<LaneElement>& lanes = store_->lanes();
  near_ = std::move(association.near);
  for (std::size_t c = 0; c < candidates.size(); ++c) {
    // The start gate looks at every point of low enough uncertainty: the N best of PS alone
    // may all lie on the nearest dash of a dashed line, shorter than the gate.
    const std::vector<Eigen::Vector3d> usable_map = UsablePoints(candidates[c]);
    if (match[c] < 0) {
      Start(candidates[c].class_id, measurements[c], usable_map, frame);
      continue;
    }
    LaneElement& lane = lanes[match[c]];
    lane.history.push_back(std::move(measurements[c]));
    lane.last_frame = frame.index;
    lane.last_seen = frame.stamp;
    store_->Touch(&lane, Grow(&lane, frame.index, usable_map));
  }
  if (store_->frames().size() % static_cast<std::size_t>(options_.lanes.merge_every_n_frames) ==
      0) {
    MergeLines();
  }
}

std::size_t LaneTracker::Grow(LaneElement* lane, std::size_t frame_index,
                              const std::vector<Eigen::Vector3d>& usable_map) const {
  const std::size_t horizon = static_cast<std::size_t>(options_.lanes.end_fit_frames);
  std::vector<Eigen::Vector3d> points;
  for (auto m = lane->history.rbegin(); m != lane->history.rend(); ++m) {
    if (m->frame_index + horizon <= frame_index) break;
    points.insert(points.end(), m->selected_map.begin(), m->selected_map.end());
  }
  // The ends grow along the driven path's curve, offset kept (path_curvature.h).
  const LaneEndCurvatures curvatures = PathEndCurvatures(
      store_->frames(), frame_index, options_.lanes.end_growth_path_length_m,
      MinGrowthCurvature(options_.association.lane_gate_m, options_.association.lane_max_end_gap_m),
      lane->control_points_map);
  int added_at_start = 0;
  std::size_t first_changed = 0;
  FitLaneEndsNear(options_.lanes.end_fit, points, usable_map, &lane->control_points_map,
                  &added_at_start, &first_changed, curvatures);
  lane->first_cp_index -= added_at_start;  // keeps older back-end results applicable
  return first_changed;
}

void LaneTracker::Start(int class_id, const LaneMeasurement& measurement,
                        const std::vector<Eigen::Vector3d>& usable_map, const FrameRecord& frame) {
  if (Extent(usable_map) < options_.lanes.min_new_lane_length_m) {
    ++counters_->lane_observations_unused;
    return;
  }
  AssociationOptions loose = options_.association;
  loose.lane_gate_m *= 2.0;
  loose.lane_gate_sigmas *= 2.0;
  const LaneCandidate candidate{class_id, usable_map, {}, {}};
  const std::vector<LaneElement>& lanes = store_->lanes();
  for (std::size_t i : near_) {
    if (LaneAssociationCost(lanes[i], candidate, loose) >= 0.0) {
      ++counters_->lane_observations_near_lane;
      return;
    }
  }
  // Along a mapped stretch of a lane of another class (a class flickering between solid and
  // dashed): the same line, not a new one. Only points beside the lane's curve count, not
  // past its ends: a line that goes on in another class still starts there. The plain gates:
  // at 0.5 m of odometry noise the loose ones reach the next lane's line, 3.5 m beside.
  AssociationOptions alongside = options_.association;
  alongside.lane_max_end_gap_m = 0.0;
  for (std::size_t i : near_) {
    const LaneElement& lane = lanes[i];
    if (lane.class_id == class_id) continue;
    const LaneCandidate as_its_class{lane.class_id, usable_map, {}, {}};
    if (LaneAssociationCost(lane, as_its_class, alongside) >= 0.0) {
      ++counters_->lane_observations_other_class;
      return;
    }
  }
  auto control_points = EstimateControlPoints(measurement.selected_map, options_.lanes.fit);
  if (!control_points) control_points = EstimateControlPoints(usable_map, options_.lanes.fit);
  if (!control_points) {
    ++counters_->lane_observations_unused;
    return;
  }
  // Ordered along the direction of travel, so that the lane mostly grows at its end.
  const Eigen::Vector3d heading = frame.T_map_base.linear().col(0);
  if ((control_points->back() - control_points->front()).dot(heading) < 0.0) {
    std::reverse(control_points->begin(), control_points->end());
  }
  LaneElement lane;
  lane.id = store_->NewId();
  lane.class_id = class_id;
  lane.control_points_map = std::move(*control_points);
  lane.history.push_back(measurement);
  lane.first_frame = lane.last_frame = frame.index;
  lane.first_seen = lane.last_seen = frame.stamp;
  store_->Touch(&lane);
  store_->lanes().push_back(std::move(lane));
  near_.push_back(store_->lanes().size() - 1);  // the frame's next candidates see it
  ++counters_->lanes_created;
}

std::vector<Eigen::Vector3d> LaneTracker::RefitControlPoints(
    const LaneElement& lane, const CameraIntrinsics& camera,
    const Eigen::Isometry3d& T_base_cam) const {
  const PinholeCamera pinhole(camera);
  std::vector<Eigen::Vector3d> points;
  for (const LaneMeasurement& m : lane.history) {
    const FrameRecord& frame = store_->frames()[m.frame_index];
    const Eigen::Isometry3d& T_map_base = frame.T_map_base;
    // The ground the front end mapped this frame's pixels onto.
    const Ipm ipm(pinhole, T_base_cam, options_.ipm.max_range_m, frame.ground_base);
    for (std::size_t i = 0; i < m.points.size(); ++i) {
      Eigen::Vector3d p_base;
      if (m.selected[i] && ipm.PixelToGround(m.points[i].uv, &p_base) == IpmStatus::kOk) {
        points.push_back(T_map_base * p_base);
      }
    }
  }
  return FitLaneEnds(lane.control_points_map, points, options_.lanes.end_fit);
}

void LaneTracker::MergeLines() {
  // Two lanes of one class that turn out to be one line (e.g. one was started while the
  // other was not matched across a gap): the second's curve lies along the first.
  std::vector<LaneElement>& lanes = store_->lanes();
  std::vector<std::size_t> near = LanesThatMayHaveChanged();
  for (std::size_t ai = 0; ai < near.size(); ++ai) {
    for (std::size_t bi = ai + 1; bi < near.size();) {
      const std::size_t b = near[bi];
      LaneElement& first = lanes[near[ai]];
      LaneElement& second = lanes[b];
      if (first.class_id != second.class_id) {
        ++bi;
        continue;
      }
      const LaneCandidate candidate = SampledCandidate(second);
      if (candidate.points_map.size() < 2 ||
          LaneAssociationCost(first, candidate, options_.association) < 0.0) {
        ++bi;
        continue;
      }
      MergeObservations(second, &first);
      // Grow `first` over the second's stretch; its own control points keep their indices.
      std::vector<Eigen::Vector3d> points;
      for (const LaneMeasurement& m : second.history) {
        points.insert(points.end(), m.selected_map.begin(), m.selected_map.end());
      }
      int added_at_start = 0;
      auto fitted =
          FitLaneEnds(first.control_points_map, points, options_.lanes.end_fit, &added_at_start);
      const std::size_t changed_from = FirstChangedControlPoint(first.control_points_map, fitted);
      first.control_points_map = std::move(fitted);
      first.first_cp_index -= added_at_start;
      store_->Touch(&first, added_at_start > 0 ? 0 : changed_from);
      lanes.erase(lanes.begin() + static_cast<std::ptrdiff_t>(b));
      near.erase(near.begin() + static_cast<std::ptrdiff_t>(bi));
      for (std::size_t k = bi; k < near.size(); ++k) --near[k];  // past b: one place down
      ++counters_->lanes_merged;
    }
  }
  JoinFragments(SettledBefore());
}

double LaneTracker::AssociationMarginM() const {
  // LaneAssociationCost's margin about the points (association.cpp).
  return options_.association.lane_max_end_gap_m + 5.0;
}

std::vector<std::size_t> LaneTracker::LanesThatMayHaveChanged() const {
  // A lane changes while frames see it (growth, merges) or a window solves it: within the
  // camera's range of the frames since the last merge or of the windows' frames. A merge or
  // join pairs it with a lane within reach of it (the association's margin; a join's gap,
  // overlap and two end models). Pairs of lanes that did not change were decided before.
  const std::vector<FrameRecord>& frames = store_->frames();
  if (frames.empty()) return {};
  const std::size_t n = frames.size();
  const std::size_t interval = static_cast<std::size_t>(options_.lanes.merge_every_n_frames);
  const std::size_t from = std::min(SettledBefore(), n > interval ? n - interval : 0);
  const Eigen::Vector3d now = frames.back().T_map_base.translation();
  double travel_m = 0.0;
  for (std::size_t i = from; i < n; ++i) {
    travel_m = std::max(travel_m, (frames[i].T_map_base.translation() - now).head<2>().norm());
  }
  const LaneJoinOptions& join = options_.lanes.join;
  const double reach_m =
      std::max(AssociationMarginM(), join.max_gap_m + join.max_overlap_m + 2.0 * join.end_length_m);
  return store_->LanesNear(now, travel_m + options_.ipm.max_range_m + reach_m);
}

std::size_t LaneTracker::SettledBefore() const {
  const std::size_t frames = store_->frames().size();
  const BackendOptions& backend = options_.backend;
  if (!backend.enabled || backend.lane_residual == LaneResidual::kNone) return frames;
  return LaneContextStart(backend, frames);
}

void LaneTracker::DropSpurious(std::size_t frame_index) {
  const std::size_t horizon = options_.association.spurious_after_frames;
  std::vector<LaneElement>& lanes = store_->lanes();
  const std::size_t before = lanes.size();
  lanes.erase(std::remove_if(lanes.begin(), lanes.end(),
                             [&](const LaneElement& e) {
                               return e.Observations() == 1 && frame_index > e.last_frame + horizon;
                             }),
              lanes.end());
  counters_->spurious_dropped += before - lanes.size();
}

}  // namespace ipm_road_mapper
