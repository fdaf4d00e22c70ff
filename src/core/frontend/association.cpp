#include "ipm_road_mapper/core/frontend/association.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <tuple>

#include "ipm_road_mapper/core/frontend/partial_view_association.h"
#include "ipm_road_mapper/core/geometry/catmull_rom_spline.h"
#include "ipm_road_mapper/core/geometry/lane_end_line.h"

namespace ipm_road_mapper {

AssociationOptions LoadAssociationOptions(OptionsReader reader) {
  AssociationOptions o;
  reader.Read<double>("marking_gate_sigmas", &o.marking_gate_sigmas, CheckPositive);
  reader.Read<double>("marking_position_sigma_m", &o.marking_position_sigma_m, CheckPositive);
  reader.Read<double>("marking_merge_distance_m", &o.marking_merge_distance_m, CheckNonNegative);
  reader.Read<double>("marking_merge_overlap", &o.marking_merge_overlap, CheckProbability);
  reader.Read<double>("lane_max_point_score_m2", &o.lane_max_point_score_m2, CheckPositive);
  reader.Read<double>("lane_gate_m", &o.lane_gate_m, CheckPositive);
  reader.Read<double>("lane_gate_sigmas", &o.lane_gate_sigmas, CheckPositive);
  reader.Read<double>("lane_position_sigma_m", &o.lane_position_sigma_m, CheckPositive);
  reader.Read<double>("lane_min_direction_cos", &o.lane_min_direction_cos, CheckProbability);
  reader.Read<double>("lane_max_end_gap_m", &o.lane_max_end_gap_m, CheckNonNegative);
  reader.Read<double>("lane_min_support", &o.lane_min_support, CheckProbability);
  reader.Read<int>("spurious_after_frames", &o.spurious_after_frames, CheckPositiveInt);
  reader.RejectUnknownKeys();
  return o;
}

int BestCyclicShift(const std::array<Eigen::Vector3d, 4>& element,
                    const std::array<Eigen::Vector3d, 4>& observation, double* mean_distance_m) {
  int best_shift = 0;
  double best_sum = std::numeric_limits<double>::infinity();
  for (int shift = 0; shift < 4; ++shift) {
    double sum = 0.0;
    for (int i = 0; i < 4; ++i) sum += (element[i] - observation[(i + shift) % 4]).norm();
    if (sum < best_sum) {
      best_sum = sum;
      best_shift = shift;
    }
  }
  if (mean_distance_m) *mean_distance_m = best_sum / 4.0;
  return best_shift;
}

namespace {

// Greedy one-to-one assignment over (cost, candidate, element) triples.
std::vector<int> AssignGreedy(std::vector<std::tuple<double, int, int>> pairs, int num_candidates,
                              int num_elements) {
  std::sort(pairs.begin(), pairs.end());
  std::vector<int> assignment(num_candidates, -1);
  std::vector<bool> element_taken(num_elements, false);
  for (const auto& [cost, candidate, element] : pairs) {
    if (assignment[candidate] >= 0 || element_taken[element]) continue;
    assignment[candidate] = element;
    element_taken[element] = true;
  }
  return assignment;
}

Eigen::Vector3d Mean(const std::array<Eigen::Vector3d, 4>& corners) {
  return 0.25 * (corners[0] + corners[1] + corners[2] + corners[3]);
}

}  // namespace

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

namespace {

// Smallest area ratio of two whole views of one marking (see AssociateMarkings).
constexpr double kMinAreaRatio = 1.0 / 3.0;

// Area (x-y) of a 4-corner polygon.
double RectangleArea(const std::array<Eigen::Vector3d, 4>& c) {
  double twice = 0.0;
  for (int i = 0; i < 4; ++i) {
    twice += c[i].x() * c[(i + 1) % 4].y() - c[(i + 1) % 4].x() * c[i].y();
  }
  return 0.5 * std::abs(twice);
}

}  // namespace

namespace {

// A candidate whose points span more than this (m, horizontally) is compared with the lane
// near each point rather than with one piece of the lane around all of them.
constexpr double kMaxSharedCurveExtentM = 100.0;

// The part of a lane's curve near some points: a sub-spline, and whether it holds the lane's
// start and end.
struct LocalCurve {
  CatmullRomSpline spline;
  bool has_start = false;
  bool has_end = false;
};

std::optional<LocalCurve> LocalCurveNear(const std::vector<Eigen::Vector3d>& cps,
                                         const std::vector<Eigen::Vector3d>& points,
                                         double margin_m) {
  std::size_t first = 0, last = 0;
  if (!ControlPointRangeNear(cps, points, margin_m, &first, &last)) return std::nullopt;
  return LocalCurve{
      CatmullRomSpline(std::vector<Eigen::Vector3d>(cps.begin() + first, cps.begin() + last + 1)),
      first == 0, last + 1 == cps.size()};
}

// Whether the points' horizontal bounding box is wider or longer than `extent_m`.
bool IsSpread(const std::vector<Eigen::Vector3d>& points, double extent_m) {
  Eigen::Vector2d lo = points.front().head<2>(), hi = lo;
  for (const Eigen::Vector3d& p : points) {
    lo = lo.cwiseMin(p.head<2>());
    hi = hi.cwiseMax(p.head<2>());
  }
  return ((hi - lo).array() > extent_m).any();
}

}  // namespace

double MarkingFloorSigma(const AssociationOptions& options) {
  return std::hypot(options.marking_position_sigma_m, options.odometry_sigma_m);
}

double LaneFloorSigma(const AssociationOptions& options) {
  return std::hypot(options.lane_position_sigma_m, options.odometry_sigma_m);
}

double LaneGateM(const AssociationOptions& options) {
  return std::max(options.lane_gate_m, options.lane_gate_sigmas * LaneFloorSigma(options));
}

double LaneNoiseShare(const AssociationOptions& options) {
  return options.lane_gate_sigmas * LaneFloorSigma(options) / LaneGateM(options);
}

double LaneEndLineLength(const AssociationOptions& options) {
  const double share = LaneNoiseShare(options);
  return options.lane_max_end_gap_m * share * share;
}

double MarkingAssociationCost(const MarkingElement& element, const MarkingCandidate& candidate,
                              const AssociationOptions& options) {
  // Compare in x-y: the mapped z of a marking is refined later, the gate is planar.
  const Eigen::Vector2d d = (element.Center() - Mean(candidate.corners_map)).head<2>();
  const double floor = std::pow(MarkingFloorSigma(options), 2);
  const Eigen::Matrix2d S =
      candidate.center_cov_map + element.center_cov_map + floor * Eigen::Matrix2d::Identity();
  return d.dot(S.ldlt().solve(d));
}

std::vector<int> AssociateMarkings(const std::vector<MarkingElement>& elements,
                                   const std::vector<MarkingCandidate>& candidates,
                                   const AssociationOptions& options) {
  std::vector<const MarkingElement*> pointers;
  pointers.reserve(elements.size());
  for (const MarkingElement& e : elements) pointers.push_back(&e);
  return AssociateMarkings(pointers, candidates, options);
}

double MarkingGateRadius(const MarkingCandidate& candidate, double max_element_cov_trace,
                         const AssociationOptions& options) {
  const double floor = std::pow(MarkingFloorSigma(options), 2);
  const double trace = candidate.center_cov_map.trace() + max_element_cov_trace + 2.0 * floor;
  return options.marking_gate_sigmas * std::sqrt(std::max(0.0, trace));
}

std::vector<int> AssociateMarkings(const std::vector<const MarkingElement*>& elements,
                                   const std::vector<MarkingCandidate>& candidates,
                                   const AssociationOptions& options) {
  std::vector<std::tuple<double, int, int>> pairs;
  const double gate = options.marking_gate_sigmas * options.marking_gate_sigmas;
  for (int c = 0; c < static_cast<int>(candidates.size()); ++c) {
    for (int e = 0; e < static_cast<int>(elements.size()); ++e) {
      if (elements[e]->class_id != candidates[c].class_id) continue;
      // Two whole views of one marking have about one area (IPM stretches a far view by
      // tens of percent, not 3x): a blob inside a marking is not a view of it.
      if (candidates[c].complete && elements[e]->Complete()) {
        const double a = RectangleArea(candidates[c].corners_map);
        const double b = RectangleArea(elements[e]->corners_map);
        if (!(std::min(a, b) >= kMinAreaRatio * std::max(a, b))) continue;
      }
      double cost = MarkingAssociationCost(*elements[e], candidates[c], options);
      if (!candidates[c].complete || !elements[e]->Complete()) {
        // A partial view: the shared area decides (full overlap costs nothing).
        const double overlap =
            OverlapOfSmaller(elements[e]->corners_map, candidates[c].corners_map);
        if (overlap >= options.marking_merge_overlap && overlap > 0.0) {
          cost = std::min(cost, gate * (1.0 - overlap));
        }
        // Or, for an element never seen whole (larger than the view: its center is where
        // the views ended), its measured sides lie on the element's (PartialViewCost). An
        // element seen whole keeps the center gate: its center is measured, and a crossing's
        // stripes 1 m apart are within the sides' gate of each other.
        if (!elements[e]->Complete()) {
          const double sides = PartialViewCost(*elements[e], candidates[c], options);
          if (sides >= 0.0) cost = std::min(cost, sides);
        }
      }
      if (cost <= gate) pairs.emplace_back(cost, c, e);
    }
  }
  return AssignGreedy(std::move(pairs), static_cast<int>(candidates.size()),
                      static_cast<int>(elements.size()));
}

double LaneAssociationCost(const LaneElement& lane, const LaneCandidate& candidate,
                           const AssociationOptions& options) {
  if (lane.class_id != candidate.class_id || lane.control_points_map.size() < 4 ||
      candidate.points_map.size() < 2) {
    return -1.0;
  }
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Matrix2d> covs;
  for (std::size_t i = 0; i < candidate.points_map.size(); ++i) {
    if (!candidate.usable.empty() && !candidate.usable[i]) continue;
    points.push_back(candidate.points_map[i]);
    covs.push_back(candidate.cov_map.empty() ? Eigen::Matrix2d::Zero() : candidate.cov_map[i]);
  }
  if (points.size() < 2) return -1.0;
  // The lines past the lane's ends, fitted on first use (most candidates reach neither).
  std::optional<LaneEndLine> start_line, end_line;
  const double end_line_length_m = LaneEndLineLength(options);
  const double floor = std::pow(LaneFloorSigma(options), 2);
  const double gate_m = LaneGateM(options);
  // Only the part of the lane near the observation (a lane can be kilometers long); the
  // margin covers points past an end that still count. A candidate longer than an
  // observation (a whole lane, when lanes are merged) gets the part near each of its points,
  // so that the cost does not grow with the lanes' lengths.
  const double margin_m = options.lane_max_end_gap_m + 5.0;
  std::optional<LocalCurve> shared;
  if (!IsSpread(points, kMaxSharedCurveExtentM)) {
    shared = LocalCurveNear(lane.control_points_map, points, margin_m);
    if (!shared) return -1.0;
  }
  // Observation direction: from its first to its last point (ordered along the lane).
  Eigen::Vector2d obs_dir = (points.back() - points.front()).head<2>();
  if (obs_dir.norm() < 1e-6) return -1.0;
  obs_dir.normalize();

  // Use at most ~12 points spread over the observation: association runs every frame.
  const std::size_t n = points.size();
  const std::size_t step = std::max<std::size_t>(1, n / 12);
  std::vector<double> lateral, normalized;
  int used = 0, direction_votes = 0, direction_ok = 0;
  for (std::size_t i = 0; i < n; i += step, ++used) {
    const Eigen::Vector3d& p = points[i];
    std::optional<LocalCurve> own;
    if (!shared) {
      own = LocalCurveNear(lane.control_points_map, {p}, margin_m);
      if (!own) {
        // Farther than the margin from the whole lane: beside it, as with one shared piece.
        lateral.push_back(std::numeric_limits<double>::infinity());
        normalized.push_back(std::numeric_limits<double>::infinity());
        ++direction_votes;
        ++direction_ok;
        continue;
      }
    }
    const LocalCurve& curve = shared ? *shared : *own;
    const CatmullRomSpline& spline = curve.spline;
    const CatmullRomSpline::ClosestPoint closest = spline.FindClosest(p);
    Eigen::Vector2d tangent = spline.Derivative(closest.s).head<2>();
    if (tangent.norm() < 1e-9) continue;
    tangent.normalize();
    const double end_s = spline.NumSegments();
    const bool past_start = curve.has_start && closest.s <= 1e-6;
    const bool past_end = !past_start && curve.has_end && closest.s >= end_s - 1e-6;
    double lateral_m = (p - closest.point).head<2>().norm();
    if (past_start || past_end) {
      // Past an end, the distance to the line the lane's last stretch continues along.
      std::optional<LaneEndLine>& line = past_end ? end_line : start_line;
      if (!line) line = FitLaneEndLine(lane.control_points_map, past_end, end_line_length_m);
      if (!line->valid) continue;
      double along = 0.0;
      lateral_m = DistanceFromEndLine(*line, p, &along);
      if (along > options.lane_max_end_gap_m) continue;
      tangent = line->Direction();
    }
    // The point's IPM variance across the lane (normal n of the tangent) plus the floor.
    const Eigen::Vector2d normal(-tangent.y(), tangent.x());
    const double variance = normal.dot(covs[i] * normal) + floor;
    lateral.push_back(lateral_m);
    normalized.push_back(lateral_m / std::sqrt(variance));
    ++direction_votes;
    if (std::abs(tangent.dot(obs_dir)) >= options.lane_min_direction_cos) ++direction_ok;
  }
  if (used == 0 || lateral.size() < std::max<std::size_t>(2, options.lane_min_support * used)) {
    return -1.0;
  }
  if (direction_ok * 2 < direction_votes) return -1.0;
  const std::size_t mid = lateral.size() / 2;
  std::nth_element(lateral.begin(), lateral.begin() + mid, lateral.end());
  std::nth_element(normalized.begin(), normalized.begin() + mid, normalized.end());
  if (lateral[mid] > gate_m || normalized[mid] > options.lane_gate_sigmas) return -1.0;
  return normalized[mid];
}

double LaneOffsetAcross(const LaneElement& lane, const LaneCandidate& candidate,
                        const Eigen::Vector2d& left) {
  std::vector<Eigen::Vector3d> points;
  for (std::size_t i = 0; i < candidate.points_map.size(); ++i) {
    if (!candidate.usable.empty() && !candidate.usable[i]) continue;
    if (candidate.points_map[i].allFinite()) points.push_back(candidate.points_map[i]);
  }
  if (points.size() < 2 || lane.control_points_map.size() < 4) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  const std::optional<LocalCurve> curve = LocalCurveNear(lane.control_points_map, points, 5.0);
  if (!curve) return std::numeric_limits<double>::quiet_NaN();
  const double end_s = curve->spline.NumSegments();
  const std::size_t step = std::max<std::size_t>(1, points.size() / 12);
  std::vector<double> offsets;
  for (std::size_t i = 0; i < points.size(); i += step) {
    const CatmullRomSpline::ClosestPoint closest = curve->spline.FindClosest(points[i]);
    if ((curve->has_start && closest.s <= 1e-6) || (curve->has_end && closest.s >= end_s - 1e-6)) {
      continue;  // past an end: no offset across
    }
    offsets.push_back((closest.point - points[i]).head<2>().dot(left));
  }
  if (offsets.size() < 2) return std::numeric_limits<double>::quiet_NaN();
  const std::size_t mid = offsets.size() / 2;
  std::nth_element(offsets.begin(), offsets.begin() + mid, offsets.end());
  return offsets[mid];
}

std::vector<int> AssociateLanes(const std::vector<LaneElement>& lanes,
                                const std::vector<LaneCandidate>& candidates,
                                const AssociationOptions& options) {
  std::vector<std::size_t> all(lanes.size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
  return AssociateLanes(lanes, all, candidates, options);
}

std::vector<int> AssociateLanes(const std::vector<LaneElement>& lanes,
                                const std::vector<std::size_t>& among,
                                const std::vector<LaneCandidate>& candidates,
                                const AssociationOptions& options) {
  // Pairs by position in `among`: ascending, so ties break as over all lanes.
  std::vector<std::tuple<double, int, int>> pairs;
  for (int c = 0; c < static_cast<int>(candidates.size()); ++c) {
    for (int k = 0; k < static_cast<int>(among.size()); ++k) {
      const double cost = LaneAssociationCost(lanes[among[k]], candidates[c], options);
      if (cost >= 0.0) pairs.emplace_back(cost, c, k);
    }
  }
  std::vector<int> match = AssignGreedy(std::move(pairs), static_cast<int>(candidates.size()),
                                        static_cast<int>(among.size()));
  for (int& m : match) {
    if (m >= 0) m = static_cast<int>(among[m]);
  }
  return match;
}

}  // namespace ipm_road_mapper
