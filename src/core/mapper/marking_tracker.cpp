#include "ipm_road_mapper/core/mapper/marking_tracker.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "ipm_road_mapper/core/frontend/association.h"
#include "ipm_road_mapper/core/frontend/frame_registration.h"
#include "ipm_road_mapper/core/frontend/instance_extraction.h"
#include "ipm_road_mapper/core/mapper/far_marking_estimate.h"
#include "ipm_road_mapper/core/mapper/marking_extent.h"
#include "ipm_road_mapper/core/mapper/marking_pixel_agreement.h"
#include "ipm_road_mapper/core/mapper/partial_extent_on_road.h"
#include "ipm_road_mapper/core/mapper/shared_frames.h"

namespace ipm_road_mapper {
namespace {

// The measurement of an observation in its element's corner order: element corner i is the
// observation's corner (i + shift) % 4, element side i its side (i + shift) % 4.
MarkingMeasurement MeasurementOf(const MarkingObservation& obs, std::size_t frame_index,
                                 int shift) {
  MarkingMeasurement measurement;
  measurement.frame_index = frame_index;
  for (int i = 0; i < 4; ++i) {
    measurement.corners_uv[i] = obs.corners_uv[(i + shift) % 4];
    measurement.corners_base[i] = obs.corners_base[(i + shift) % 4];
    measurement.side_measured[i] = obs.side_measured[(i + shift) % 4];
    measurement.side_uv[i] = obs.side_uv[(i + shift) % 4];
  }
  measurement.outline_uv = obs.outline_uv;
  return measurement;
}

// Below this angle (rad) from base_link's x axis the extracted rectangle is kept.
constexpr double kRoadAxisMinAngleRad = 1e-3;

// A tentative marking is confirmed once seen this many times, in at least kMinSeenFraction
// of the frames that should have seen it; it is dropped as inconsistent once those frames
// are kMinExpectedToJudge or more and it was seen in fewer than that fraction. A real
// marking is missed now and then (2 % in the synthetic drives); a spurious blob is one
// frame's error and is not there in the next frames.
constexpr std::size_t kMinSeenToConfirm = 3;
constexpr double kMinSeenFraction = 0.5;
constexpr std::size_t kMinExpectedToJudge = 4;

// The weight of a far view in a far-only element's mean: the inverse of its center's
// plain-IPM variance (Omega_p's x-y trace, m^2).
double FarViewWeight(const MarkingCandidate& candidate) {
  return 1.0 / std::max(candidate.center_cov_map.trace(), 1e-6);
}

// An element made by one view.
MarkingElement NewElement(const MarkingObservation& obs, const MarkingCandidate& candidate,
                          const FrameRecord& frame) {
  MarkingElement element;
  element.class_id = obs.class_id;
  element.corners_map = candidate.corners_map;
  element.center_cov_map = candidate.center_cov_map;
  element.side_measured = obs.side_measured;
  for (int s = 0; s < 4; ++s) element.side_views[s] = obs.side_measured[s] ? 1 : 0;
  element.history.push_back(MeasurementOf(obs, frame.index, 0));
  element.first_frame = element.last_frame = frame.index;
  element.first_seen = element.last_seen = frame.stamp;
  element.farthest_view_m = obs.center_base.head<2>().norm();
  element.far_only = obs.far;
  if (obs.far) element.far_weight = FarViewWeight(candidate);
  return element;
}

// Replaces a far-only element by `fresh` (made by a near view), keeping its id and what the
// incremental export knows of it. Its confirmation starts again with the near views: from
// here on it is the element they alone would have made.
void RestartFromNearView(MarkingElement fresh, MarkingElement* element) {
  fresh.id = element->id;
  fresh.revision = element->revision;
  fresh.exported_at = element->exported_at;
  fresh.retired = element->retired;
  *element = std::move(fresh);
}

// Largest horizontal distance of a corner from the center.
double Radius(const MarkingElement& e) {
  double r = 0.0;
  for (const Eigen::Vector3d& c : e.corners_map) r = std::max(r, (c - e.Center()).head<2>().norm());
  return r;
}

// Moves `second`'s measurements into `first` (in first's corner order, one per frame: the
// first's where both have one) and widens first's span.
void Absorb(MarkingElement* first, const MarkingElement& second) {
  const int shift = BestCyclicShift(first->corners_map, second.corners_map, nullptr);
  for (const MarkingMeasurement& m : second.history) {
    MarkingMeasurement reordered = m;
    for (int i = 0; i < 4; ++i) {
      reordered.corners_uv[i] = m.corners_uv[(i + shift) % 4];
      reordered.corners_base[i] = m.corners_base[(i + shift) % 4];
    }
    first->history.push_back(std::move(reordered));
  }
  std::sort(first->history.begin(), first->history.end(),
            [](const MarkingMeasurement& x, const MarkingMeasurement& y) {
              return x.frame_index < y.frame_index;
            });
  first->history.erase(std::unique(first->history.begin(), first->history.end(),
                                   [](const MarkingMeasurement& x, const MarkingMeasurement& y) {
                                     return x.frame_index == y.frame_index;
                                   }),
                       first->history.end());
  first->first_frame = std::min(first->first_frame, second.first_frame);
  first->last_frame = std::max(first->last_frame, second.last_frame);
  first->first_seen = std::min(first->first_seen, second.first_seen);
  first->last_seen = std::max(first->last_seen, second.last_seen);
  first->pruned += second.pruned;
  first->optimized = first->optimized || second.optimized;
  first->confirmed = first->confirmed || second.confirmed;
  first->frames_seen += second.frames_seen;
  first->frames_expected = std::max(first->frames_expected, second.frames_expected);
  first->farthest_view_m = std::max(first->farthest_view_m, second.farthest_view_m);
  first->far_weight += second.far_weight;
  first->near_frames_expected = std::max(first->near_frames_expected, second.near_frames_expected);
  if (second.center_cov_map.trace() < first->center_cov_map.trace()) {
    first->center_cov_map = second.center_cov_map;
  }
}

}  // namespace

MarkingTracker::MarkingTracker(const MapperOptions& options, MapStore* store,
                               MapperCounters* counters)
    : options_(options), store_(store), counters_(counters) {}

void MarkingTracker::Update(const Ipm& ipm, const FrameRecord& frame,
                            std::vector<MarkingObservation>* observations,
                            std::optional<double> offset_across_m,
                            const RoadPlane* road_ahead_map) {
  OrientAlongRoad(ipm, frame, observations);

  Associate(*observations, frame, offset_across_m);
  RefreshFarOnly(ipm.camera(), ipm.T_base_cam(), /*include_retired=*/false, road_ahead_map);
  CheckConsistency(ipm, frame);
  MergeDuplicates(ipm);
}

void MarkingTracker::OrientAlongRoad(const Ipm& ipm, const FrameRecord& frame,
                                     std::vector<MarkingObservation>* observations) {
  if (store_->lanes().empty()) return;
  const Eigen::Isometry3d T_base_map = frame.T_map_base.inverse();
  for (auto it = observations->begin(); it != observations->end();) {
    const Eigen::Vector3d tangent_map = store_->RoadDirectionAt(frame.T_map_base * it->center_base);
    Eigen::Vector2d axis_base = (T_base_map.linear() * tangent_map).head<2>();
    if (axis_base.norm() < 1e-9 ||
        std::abs(std::atan2(axis_base.y(), axis_base.x())) < kRoadAxisMinAngleRad) {
      ++it;
      continue;
    }
    if (axis_base.x() < 0.0) axis_base = -axis_base;  // a rectangle has no direction
    if (SetMarkingRectangle(ipm, options_.ipm.error_model, axis_base, &*it)) {
      ++it;
    } else {
      it = observations->erase(it);  // its re-oriented corner leaves the image: not usable
      ++counters_->extraction.dropped_range;
    }
  }
}

void MarkingTracker::Associate(const std::vector<MarkingObservation>& observations,
                               const FrameRecord& frame, std::optional<double> offset_across_m) {
  std::vector<MarkingCandidate> candidates;
  candidates.reserve(observations.size());
  const Eigen::Matrix2d R = frame.T_map_base.linear().topLeftCorner<2, 2>();
  for (const MarkingObservation& obs : observations) {
    MarkingCandidate candidate;
    candidate.class_id = obs.class_id;
    for (int i = 0; i < 4; ++i) candidate.corners_map[i] = frame.T_map_base * obs.corners_base[i];
    candidate.center_cov_map = R * obs.center_cov_base * R.transpose();
    candidate.complete = obs.Complete();
    candidate.side_measured = obs.side_measured;
    candidates.push_back(candidate);
  }
  // The live markings and the retired ones within the gate of some candidate (re-observed
  // after a gap: a marking is one element however often it is seen).
  std::vector<MarkingElement>& markings = store_->markings();
  std::vector<const MarkingElement*> elements;
  for (const MarkingElement& m : markings) elements.push_back(&m);
  std::vector<std::size_t> retired_near;
  for (const MarkingCandidate& c : candidates) {
    const Eigen::Vector3d center =
        0.25 * (c.corners_map[0] + c.corners_map[1] + c.corners_map[2] + c.corners_map[3]);
    double radius = MarkingGateRadius(c, store_->max_retired_cov_trace(), options_.association);
    // A partial view can lie anywhere on a larger element: search as far as it reaches again.
    if (!c.complete) {
      for (const Eigen::Vector3d& corner : c.corners_map) {
        radius = std::max(radius, 2.0 * (corner - center).head<2>().norm());
      }
    }
    for (std::size_t i : store_->RetiredMarkingsNear(center, radius)) retired_near.push_back(i);
  }
  std::sort(retired_near.begin(), retired_near.end());
  retired_near.erase(std::unique(retired_near.begin(), retired_near.end()), retired_near.end());
  for (std::size_t i : retired_near) elements.push_back(&store_->retired_markings()[i]);
  // In the frame registered across the road by its lanes, where the noise sets the gates.
  std::vector<int> match = AssociateMarkingsRegistered(
      elements, candidates, options_.association,
      frame.T_map_base.linear().col(0).head<2>().normalized(), offset_across_m);
  // Matched retired markings come back among the live ones (highest retired index first:
  // a revival moves the last retired marking into the freed place).
  const int live_count = static_cast<int>(markings.size());
  std::vector<std::pair<std::size_t, std::size_t>> revive;  // (retired index, candidate)
  for (std::size_t c = 0; c < match.size(); ++c) {
    if (match[c] >= live_count) revive.emplace_back(retired_near[match[c] - live_count], c);
  }
  std::sort(revive.rbegin(), revive.rend());
  for (const auto& [retired_index, c] : revive) {
    match[c] = static_cast<int>(store_->ReviveMarking(retired_index));
  }
  for (std::size_t c = 0; c < candidates.size(); ++c) {
    const MarkingObservation& obs = observations[c];
    if (match[c] < 0) {
      MarkingElement element = NewElement(obs, candidates[c], frame);
      element.id = store_->NewId();
      store_->Touch(&element);
      markings.push_back(std::move(element));
      ++counters_->markings_created;
      continue;
    }
    MarkingElement& element = markings[match[c]];
    // A nearer view locates the marking: a far one is no measurement of it. A far-only
    // element seen near starts again from that view (as if the view had made it).
    if (obs.far && !element.far_only) continue;
    if (!obs.far && element.far_only) {
      MarkingElement fresh = NewElement(obs, candidates[c], frame);
      RestartFromNearView(std::move(fresh), &element);
      store_->Touch(&element);
      ++counters_->far_markings_restarted;
      continue;
    }
    store_->Touch(&element);
    // Whole views pair corners by distance (as always); a partial view by side direction.
    const bool whole = element.Complete() && candidates[c].complete;
    const int shift = whole
                          ? BestCyclicShift(element.corners_map, candidates[c].corners_map, nullptr)
                          : SideAlignedShift(element.corners_map, candidates[c].corners_map);
    const MarkingMeasurement measurement = MeasurementOf(obs, frame.index, shift);
    element.history.push_back(measurement);
    element.last_frame = frame.index;
    element.last_seen = frame.stamp;
    element.farthest_view_m = std::max(element.farthest_view_m, obs.center_base.head<2>().norm());
    if (candidates[c].center_cov_map.trace() < element.center_cov_map.trace()) {
      element.center_cov_map = candidates[c].center_cov_map;
    }
    std::array<Eigen::Vector3d, 4> observed_map;
    for (int i = 0; i < 4; ++i) observed_map[i] = candidates[c].corners_map[(i + shift) % 4];
    if (whole && !element.optimized) {
      // Plain IPM estimate: the running mean of the observed corners in the map (far views:
      // weighted by their Omega_p, whose range error grows as d^2).
      double step = 1.0 / static_cast<double>(element.Observations());
      if (element.far_only) {
        const double weight = FarViewWeight(candidates[c]);
        element.far_weight += weight;
        step = weight / element.far_weight;
      }
      for (int i = 0; i < 4; ++i) {
        element.corners_map[i] += step * (observed_map[i] - element.corners_map[i]);
        ++element.side_views[i];
      }
      continue;
    }
    if (whole) continue;  // the back end owns the estimate
    UpdateExtent(observed_map, measurement.side_measured, element.optimized, &element);
  }
}

void MarkingTracker::CheckConsistency(const Ipm& ipm, const FrameRecord& frame) {
  const Eigen::Isometry3d T_base_map = frame.T_map_base.inverse();
  const CameraIntrinsics& in = ipm.camera().intrinsics();
  const double near_range_m = options_.extraction.max_marking_range_m;
  for (MarkingElement& m : store_->markings()) {
    if (m.retired) continue;
    const bool seen = m.last_frame == frame.index;
    const Eigen::Vector3d center_base = ipm.OnGround((T_base_map * m.Center()).head<2>());
    Eigen::Vector2d uv;
    const auto in_image = [&] {
      return ipm.BaseToPixel(center_base, &uv) && uv.x() >= 0.0 && uv.y() >= 0.0 &&
             uv.x() <= in.width - 1.0 && uv.y() <= in.height - 1.0;
    };
    // A far-only element come within near range: a near view should find it there.
    if (m.far_only && !seen && center_base.head<2>().norm() <= near_range_m && in_image()) {
      ++m.near_frames_expected;
    }
    // A far-only element stays on probation after its confirmation: it goes once it is seen in
    // fewer than half the frames that should have seen it (DropSpurious). Retired while its
    // estimate is still on the way into near view, it is judged by these frames.
    if (m.confirmed && !m.far_only) continue;
    // Where a view saw it already or nearer, with its center in the image: it should be seen.
    const bool expected = center_base.head<2>().norm() <= m.farthest_view_m && in_image();
    if (!seen && !expected) continue;
    ++m.frames_expected;
    if (seen) ++m.frames_seen;
    if (!m.confirmed && m.frames_seen >= kMinSeenToConfirm &&
        static_cast<double>(m.frames_seen) >= kMinSeenFraction * m.frames_expected) {
      m.confirmed = true;
      store_->Touch(&m);
    }
  }
}

void MarkingTracker::MergeDuplicates(const Ipm& ipm) {
  // Two elements of one class at one place are one marking seen twice: typically a far
  // observation that missed the element (its IPM was meters off) started a second one, or a
  // close-range view (partly outside the image's useful part) did.
  const AssociationOptions& o = options_.association;
  const double gate2 = o.marking_merge_distance_m * o.marking_merge_distance_m;
  const double floor2 = std::pow(MarkingFloorSigma(o), 2);
  const double sigma_gate2 = o.marking_gate_sigmas * o.marking_gate_sigmas;
  std::vector<MarkingElement>& markings = store_->markings();
  // Squared Mahalanobis distance of two centers under the combined uncertainty of both
  // elements' best views and the floor.
  auto gate_distance2 = [&](const MarkingElement& x, const MarkingElement& y) {
    const Eigen::Vector2d d = (x.Center() - y.Center()).head<2>();
    const Eigen::Matrix2d S =
        x.center_cov_map + y.center_cov_map + floor2 * Eigen::Matrix2d::Identity();
    return d.dot(S.ldlt().solve(d));
  };
  // Whether the uncertainty gate may merge x and y: in the gate and never seen in one frame.
  auto gate_candidates = [&](std::size_t a, std::size_t b) {
    const MarkingElement& x = markings[a];
    const MarkingElement& y = markings[b];
    // Far-only elements are uncertain by far-view IPM (meters), not by where their refreshed
    // estimate lies: they meet a near-seen element only by place (distance, overlap).
    return a != b && !y.retired && x.class_id == y.class_id && x.far_only == y.far_only &&
           gate_distance2(x, y) <= sigma_gate2 && !SeenInOneFrame(x, y);
  };
  // Whether b is a's nearest gate candidate. The gate grows with the stated odometry noise
  // (~3 m at 0.5 m), wider than the 1 m spacing of a crossing's stripes: a copy within it of
  // several stripes belongs to the nearest one, not to whichever the store lists first.
  auto nearest_candidate = [&](std::size_t a, std::size_t b) {
    const double d2 = gate_distance2(markings[a], markings[b]);
    for (std::size_t c = 0; c < markings.size(); ++c) {
      if (c == b || !gate_candidates(a, c)) continue;
      if (gate_distance2(markings[a], markings[c]) < d2) return false;
    }
    return true;
  };
  // Whether b is a's nearest element of its class never seen in one frame with it.
  auto nearest_unseen = [&](std::size_t a, std::size_t b) {
    const double d2 = (markings[a].Center() - markings[b].Center()).head<2>().squaredNorm();
    for (std::size_t c = 0; c < markings.size(); ++c) {
      if (c == a || c == b || markings[c].retired || markings[c].class_id != markings[a].class_id)
        continue;
      if ((markings[a].Center() - markings[c].Center()).head<2>().squaredNorm() < d2 &&
          !SeenInOneFrame(markings[a], markings[c])) {
        return false;
      }
    }
    return true;
  };
  // Beyond a crest (relief that flat IPM and its Omega_p do not model) the far views put a
  // marking meters short in the map, outside the uncertainty gate: their pixels still agree
  // with the element its nearer views made. The element with the better best view is the
  // model, the other's views are compared with it.
  auto pixels_agree = [&](std::size_t a, std::size_t b) {
    const MarkingElement& x = markings[a];
    const MarkingElement& y = markings[b];
    if (x.far_only != y.far_only) return false;
    if (SeenInOneFrame(x, y) || !nearest_unseen(a, b) || !nearest_unseen(b, a)) return false;
    const bool x_model = x.center_cov_map.trace() <= y.center_cov_map.trace();
    return PixelsAgree(ipm, options_.ipm.error_model, o.marking_gate_sigmas, store_->frames(),
                       x_model ? x : y, x_model ? y : x);
  };
  auto same_marking = [&](std::size_t a, std::size_t b) {
    const MarkingElement& x = markings[a];
    const MarkingElement& y = markings[b];
    const Eigen::Vector2d d = (x.Center() - y.Center()).head<2>();
    if (d.squaredNorm() <= gate2) return true;
    // Re-observed after a gap, or first seen far (IPM meters off): within the uncertainty
    // gate, never seen in one frame (two markings side by side are seen together; one
    // marking's two elements never are), and each the other's nearest such candidate.
    if (gate_candidates(a, b) && nearest_candidate(a, b) && nearest_candidate(b, a)) return true;
    if (pixels_agree(a, b)) return true;
    if (o.marking_merge_overlap <= 0.0) return false;
    if (d.norm() > Radius(x) + Radius(y)) return false;  // rectangles that cannot touch
    return OverlapOfSmaller(x.corners_map, y.corners_map) >= o.marking_merge_overlap;
  };
  for (std::size_t a = 0; a < markings.size(); ++a) {
    for (std::size_t b = a + 1; b < markings.size();) {
      if (markings[a].class_id != markings[b].class_id || markings[a].retired ||
          markings[b].retired || !same_marking(a, b)) {
        ++b;
        continue;
      }
      if (markings[a].far_only != markings[b].far_only) {
        // The element near views made stays as it is: far views are no measurement of it.
        if (markings[a].far_only) std::swap(markings[a], markings[b]);
        store_->Touch(&markings[a]);
      } else {
        // The better-observed element stays (its id and its corners).
        if (markings[b].Observations() > markings[a].Observations()) {
          std::swap(markings[a], markings[b]);
        }
        Absorb(&markings[a], markings[b]);
        store_->Touch(&markings[a]);
      }
      markings.erase(markings.begin() + b);
      ++counters_->markings_merged;
    }
  }
}

void MarkingTracker::ReestimateCorners(const CornerEstimate& estimate, bool include_retired) {
  // Moves below this (m) are not changes of the exported map.
  constexpr double kMinMoveM = 1e-3;
  const auto update = [&](MarkingElement* m) {
    const std::optional<std::array<Eigen::Vector3d, 4>> corners = estimate(*m);
    if (!corners) return false;
    double moved = 0.0;
    for (int c = 0; c < 4; ++c) moved = std::max(moved, ((*corners)[c] - m->corners_map[c]).norm());
    if (moved < kMinMoveM) return false;
    m->corners_map = *corners;
    store_->Touch(m);
    return true;
  };
  for (MarkingElement& m : store_->markings()) update(&m);
  if (!include_retired) return;
  bool moved = false;
  for (MarkingElement& m : store_->retired_markings()) moved = update(&m) || moved;
  if (moved) store_->ReindexRetiredMarkings();
}

void MarkingTracker::RefreshFarOnly(const PinholeCamera& camera,
                                    const Eigen::Isometry3d& T_base_cam, bool include_retired,
                                    const RoadPlane* road_ahead_map) {
  ReestimateCorners(
      [&](const MarkingElement& m) -> std::optional<std::array<Eigen::Vector3d, 4>> {
        if (!m.far_only) return std::nullopt;
        return FarOnlyEstimate(camera, T_base_cam, options_.ipm.error_model, *store_, m,
                               road_ahead_map);
      },
      include_retired);
}

void MarkingTracker::RemeasurePartialExtents(const PinholeCamera& camera,
                                             const Eigen::Isometry3d& T_base_cam) {
  ReestimateCorners(
      [&](const MarkingElement& m) { return PartialExtentOnRoad(camera, T_base_cam, *store_, m); },
      /*include_retired=*/true);
}

void MarkingTracker::DropSpurious(std::size_t frame_index) {
  const std::size_t horizon = options_.association.spurious_after_frames;
  std::vector<MarkingElement>& markings = store_->markings();
  const std::size_t before = markings.size();
  markings.erase(std::remove_if(markings.begin(), markings.end(),
                                [&](const MarkingElement& e) {
                                  return e.Observations() == 1 &&
                                         frame_index > e.last_frame + horizon;
                                }),
                 markings.end());
  counters_->spurious_dropped += before - markings.size();
  const std::size_t consistent_before = markings.size();
  markings.erase(std::remove_if(markings.begin(), markings.end(),
                                [&](const MarkingElement& e) {
                                  return !e.confirmed && !e.optimized &&
                                         e.frames_expected >= kMinExpectedToJudge &&
                                         static_cast<double>(e.frames_seen) <
                                             kMinSeenFraction * e.frames_expected;
                                }),
                 markings.end());
  counters_->markings_inconsistent += consistent_before - markings.size();
  // A far-only element that near views did not find where it came into their view (its far
  // views put it elsewhere than the marking's near views did: a duplicate of it, or nowhere
  // real), or that stopped being seen where it should be: confirmed or not, it goes.
  const std::size_t far_before = markings.size();
  markings.erase(std::remove_if(markings.begin(), markings.end(),
                                [&](const MarkingElement& e) {
                                  return e.far_only &&
                                         (e.near_frames_expected >= kMinExpectedToJudge ||
                                          (e.frames_expected >= kMinExpectedToJudge &&
                                           static_cast<double>(e.frames_seen) <
                                               kMinSeenFraction * e.frames_expected));
                                }),
                 markings.end());
  counters_->far_markings_dropped += far_before - markings.size();
}

}  // namespace ipm_road_mapper
