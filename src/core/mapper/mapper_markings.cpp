// The marking half of the Mapper's front end: rectangles along the road, association, new
// elements, and the plain-IPM estimate (the running mean of the observed corners) until the
// back end owns a marking.
#include <algorithm>
#include <array>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "ipm_road_mapper/core/frontend/association.h"
#include "ipm_road_mapper/core/geometry/catmull_rom_spline.h"
#include "ipm_road_mapper/core/frontend/instance_extraction.h"
#include "ipm_road_mapper/core/mapper/mapper.h"

namespace ipm_road_mapper {
namespace {

// A lane farther than this from a marking does not give it the road's direction.
constexpr double kRoadAxisMaxDistanceM = 8.0;
// Below this angle (rad) from base_link's x axis the extracted rectangle is kept.
constexpr double kRoadAxisMinAngleRad = 1e-3;

}  // namespace

Eigen::Vector3d Mapper::RoadDirectionAt(const Eigen::Vector3d& p_map) const {
  double best = kRoadAxisMaxDistanceM;
  Eigen::Vector3d tangent_map = Eigen::Vector3d::Zero();
  for (const LaneElement& lane : map_.lanes) {
    std::size_t first = 0, last = 0;  // the lane's part near p_map only
    if (!ControlPointRangeNear(lane.control_points_map, {p_map}, kRoadAxisMaxDistanceM + 5.0,
                               &first, &last)) {
      continue;
    }
    const CatmullRomSpline spline(std::vector<Eigen::Vector3d>(
        lane.control_points_map.begin() + first, lane.control_points_map.begin() + last + 1));
    const CatmullRomSpline::ClosestPoint closest = spline.FindClosest(p_map);
    if (closest.distance_m >= best) continue;
    best = closest.distance_m;
    tangent_map = spline.Derivative(closest.s);
  }
  return tangent_map.norm() > 0.0 ? tangent_map.normalized() : tangent_map;
}

void Mapper::OrientMarkingsAlongRoad(const Ipm& ipm, const FrameRecord& frame,
                                     std::vector<MarkingObservation>* markings) {
  if (map_.lanes.empty()) return;
  const Eigen::Isometry3d T_base_map = frame.T_map_base.inverse();
  for (auto it = markings->begin(); it != markings->end();) {
    const Eigen::Vector3d tangent_map = RoadDirectionAt(frame.T_map_base * it->center_base);
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
      it = markings->erase(it);  // its re-oriented corner leaves the image: not usable
      ++counters_.extraction.dropped_range;
    }
  }
}

void Mapper::AddMarkings(const FrameObservations& observations, const FrameRecord& frame) {
  std::vector<MarkingCandidate> candidates;
  candidates.reserve(observations.markings.size());
  for (const MarkingObservation& obs : observations.markings) {
    MarkingCandidate candidate;
    candidate.class_id = obs.class_id;
    for (int i = 0; i < 4; ++i) candidate.corners_map[i] = frame.T_map_base * obs.corners_base[i];
    const Eigen::Matrix2d R = frame.T_map_base.linear().topLeftCorner<2, 2>();
    candidate.center_cov_map = R * obs.center_cov_base * R.transpose();
    candidates.push_back(candidate);
  }
  const std::vector<int> match = AssociateMarkings(map_.markings, candidates, options_.association);
  for (std::size_t c = 0; c < candidates.size(); ++c) {
    const MarkingObservation& obs = observations.markings[c];
    if (match[c] < 0) {
      MarkingElement element;
      element.id = map_.next_id++;
      element.class_id = obs.class_id;
      element.corners_map = candidates[c].corners_map;
      element.center_cov_map = candidates[c].center_cov_map;
      element.history.push_back({frame.index, obs.corners_uv, obs.corners_base, obs.outline_uv});
      element.first_frame = element.last_frame = frame.index;
      element.first_seen = element.last_seen = frame.stamp;
      map_.markings.push_back(std::move(element));
      ++counters_.markings_created;
      continue;
    }
    MarkingElement& element = map_.markings[match[c]];
    const int shift = BestCyclicShift(element.corners_map, candidates[c].corners_map, nullptr);
    MarkingMeasurement measurement;
    measurement.frame_index = frame.index;
    for (int i = 0; i < 4; ++i) {
      measurement.corners_uv[i] = obs.corners_uv[(i + shift) % 4];
      measurement.corners_base[i] = obs.corners_base[(i + shift) % 4];
    }
    measurement.outline_uv = obs.outline_uv;
    element.history.push_back(measurement);
    element.last_frame = frame.index;
    element.last_seen = frame.stamp;
    if (candidates[c].center_cov_map.trace() < element.center_cov_map.trace()) {
      element.center_cov_map = candidates[c].center_cov_map;
    }
    if (element.optimized) continue;  // the back end owns the estimate
    // Plain IPM estimate: the running mean of the observed corners in the map.
    const double n = static_cast<double>(element.history.size());
    for (int i = 0; i < 4; ++i) {
      element.corners_map[i] +=
          (candidates[c].corners_map[(i + shift) % 4] - element.corners_map[i]) / n;
    }
  }
}

namespace {

// Area of the intersection of two ground rectangles (x-y), over the smaller one's area.
double OverlapOfSmaller(const std::array<Eigen::Vector3d, 4>& a,
                        const std::array<Eigen::Vector3d, 4>& b) {
  auto polygon = [](const std::array<Eigen::Vector3d, 4>& corners) {
    std::vector<cv::Point2f> p;
    for (const Eigen::Vector3d& c : corners) p.emplace_back(c.x(), c.y());
    if (cv::contourArea(p, true) < 0.0) std::reverse(p.begin(), p.end());  // counterclockwise
    return p;
  };
  const std::vector<cv::Point2f> pa = polygon(a), pb = polygon(b);
  const double smaller = std::min(cv::contourArea(pa), cv::contourArea(pb));
  if (!(smaller > 1e-6)) return 0.0;
  std::vector<cv::Point2f> intersection;
  const double area = cv::intersectConvexConvex(pa, pb, intersection, true);
  return std::max(0.0, area) / smaller;
}

}  // namespace

void Mapper::MergeMarkings() {
  // Two elements of one class at one place are one marking seen twice: typically a far
  // observation that missed the element (its IPM was meters off) started a second one, or a
  // close-range view (partly outside the image's useful part) did.
  const AssociationOptions& o = options_.association;
  const double gate2 = o.marking_merge_distance_m * o.marking_merge_distance_m;
  auto same_marking = [&](const MarkingElement& x, const MarkingElement& y) {
    const Eigen::Vector2d d = (x.Center() - y.Center()).head<2>();
    if (d.squaredNorm() <= gate2) return true;
    if (o.marking_merge_overlap <= 0.0) return false;
    // Cheap reject: rectangles that cannot touch.
    auto radius = [](const MarkingElement& e) {
      double r = 0.0;
      for (const Eigen::Vector3d& c : e.corners_map)
        r = std::max(r, (c - e.Center()).head<2>().norm());
      return r;
    };
    if (d.norm() > radius(x) + radius(y)) return false;
    return OverlapOfSmaller(x.corners_map, y.corners_map) >= o.marking_merge_overlap;
  };
  for (std::size_t a = 0; a < map_.markings.size(); ++a) {
    for (std::size_t b = a + 1; b < map_.markings.size();) {
      if (map_.markings[a].class_id != map_.markings[b].class_id || map_.markings[a].retired ||
          map_.markings[b].retired || !same_marking(map_.markings[a], map_.markings[b])) {
        ++b;
        continue;
      }
      // The better-observed element stays (its id and its corners).
      if (map_.markings[b].history.size() > map_.markings[a].history.size()) {
        std::swap(map_.markings[a], map_.markings[b]);
      }
      MarkingElement& first = map_.markings[a];
      MarkingElement& second = map_.markings[b];
      // The second's measurements in the first's corner order.
      const int shift = BestCyclicShift(first.corners_map, second.corners_map, nullptr);
      for (MarkingMeasurement m : second.history) {
        MarkingMeasurement reordered = m;
        for (int i = 0; i < 4; ++i) {
          reordered.corners_uv[i] = m.corners_uv[(i + shift) % 4];
          reordered.corners_base[i] = m.corners_base[(i + shift) % 4];
        }
        first.history.push_back(std::move(reordered));
      }
      std::sort(first.history.begin(), first.history.end(),
                [](const MarkingMeasurement& x, const MarkingMeasurement& y) {
                  return x.frame_index < y.frame_index;
                });
      // Two measurements of one frame (one-to-one association forbids it within an element):
      // keep the first's.
      first.history.erase(std::unique(first.history.begin(), first.history.end(),
                                      [](const MarkingMeasurement& x, const MarkingMeasurement& y) {
                                        return x.frame_index == y.frame_index;
                                      }),
                          first.history.end());
      first.first_frame = std::min(first.first_frame, second.first_frame);
      first.last_frame = std::max(first.last_frame, second.last_frame);
      first.first_seen = std::min(first.first_seen, second.first_seen);
      first.last_seen = std::max(first.last_seen, second.last_seen);
      first.optimized = first.optimized || second.optimized;
      if (second.center_cov_map.trace() < first.center_cov_map.trace()) {
        first.center_cov_map = second.center_cov_map;
      }
      map_.markings.erase(map_.markings.begin() + b);
      ++counters_.markings_merged;
    }
  }
}

}  // namespace ipm_road_mapper
