// Map evaluation: summaries, marking matching and APE, storage, and the whole evaluation.
// Lanes are in evaluation_lanes.cpp, extrinsic and poses in evaluation_poses.cpp, the JSON
// in evaluation_report.cpp and the table in evaluation_table.cpp.
#include "ipm_road_mapper/eval/evaluation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <tuple>

#include "ipm_road_mapper/core/geometry/catmull_rom_spline.h"

namespace ipm_road_mapper {
namespace {

// Mean corner distance under the best cyclic correspondence of the 4 corners (both sets
// are in the same rotational sense, so only the 4 cyclic shifts are tried).
double CornerError(const std::array<Eigen::Vector3d, 4>& map_corners,
                   const std::array<Eigen::Vector3d, 4>& gt_corners) {
  double best = std::numeric_limits<double>::infinity();
  for (int shift = 0; shift < 4; ++shift) {
    double sum = 0.0;
    for (int k = 0; k < 4; ++k) sum += (map_corners[k] - gt_corners[(k + shift) % 4]).norm();
    best = std::min(best, 0.25 * sum);
  }
  return best;
}

// Most candidate pairs GatedMarkingPairs collects: only markings piled on each other (a
// hostile map) come near it, and they would otherwise cost N * M memory.
constexpr std::size_t kMaxMarkingCandidates = 10'000'000;

}  // namespace

std::vector<MarkingPair> GatedMarkingPairs(const VectorMap& map,
                                           const std::vector<MarkingTarget>& targets,
                                           double gate_m) {
  std::vector<std::pair<double, int>> by_x;  // (target center x, target index)
  by_x.reserve(targets.size());
  for (std::size_t j = 0; j < targets.size(); ++j) {
    by_x.emplace_back(targets[j].center_map.x(), static_cast<int>(j));
  }
  std::sort(by_x.begin(), by_x.end());
  std::vector<MarkingPair> pairs;
  for (std::size_t i = 0; i < map.markings.size(); ++i) {
    const Eigen::Vector3d center = map.markings[i].Center();
    auto it = std::lower_bound(by_x.begin(), by_x.end(), std::make_pair(center.x() - gate_m, -1));
    for (; it != by_x.end() && it->first <= center.x() + gate_m; ++it) {
      const int j = it->second;
      if (targets[j].class_id != map.markings[i].class_id) continue;
      const double distance = (center - targets[j].center_map).norm();
      if (distance > gate_m) continue;
      pairs.push_back({distance, static_cast<int>(i), j});
      if (pairs.size() > kMaxMarkingCandidates) {
        throw MapFormatError("map markings: more than " + std::to_string(kMaxMarkingCandidates) +
                             " same-class map/GT pairs within the gate (markings piled up)");
      }
    }
  }
  std::sort(pairs.begin(), pairs.end(), [](const MarkingPair& a, const MarkingPair& b) {
    return std::tie(a.distance_m, a.map_index, a.target_index) <
           std::tie(b.distance_m, b.map_index, b.target_index);
  });
  return pairs;
}

ErrorSummary Summarize(std::vector<double> values) {
  ErrorSummary summary;
  summary.count = static_cast<int>(values.size());
  if (values.empty()) return summary;
  const double n = static_cast<double>(values.size());
  summary.mean = std::accumulate(values.begin(), values.end(), 0.0) / n;
  double squares = 0.0, deviations = 0.0;
  for (double v : values) {
    squares += v * v;
    deviations += (v - summary.mean) * (v - summary.mean);
  }
  summary.stddev = std::sqrt(deviations / n);
  summary.rmse = std::sqrt(squares / n);
  summary.max = *std::max_element(values.begin(), values.end());
  const std::size_t half = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + half, values.end());
  summary.median = values[half];
  if (values.size() % 2 == 0) {
    summary.median =
        0.5 * (summary.median + *std::max_element(values.begin(), values.begin() + half));
  }
  return summary;
}

MarkingMetrics EvaluateMarkings(const VectorMap& map, const GroundTruth& gt,
                                const EvaluationOptions& options) {
  MarkingMetrics metrics;
  metrics.map_total = static_cast<int>(map.markings.size());
  metrics.gt_total = static_cast<int>(gt.markings.size());
  for (const MapMarking& m : map.markings) {
    MapMarkingResult result;
    result.map_id = m.id;
    result.class_id = m.class_id;
    result.class_name = m.class_name;
    result.center_map = m.Center();
    result.complete = m.Complete();
    metrics.map_markings.push_back(result);
  }
  for (const GroundTruthMarking& g : gt.markings) {
    GroundTruthMarkingResult result;
    result.gt_id = g.id;
    result.class_id = g.class_id;
    result.class_name = g.class_name;
    result.visible_frames = g.visible_frames;
    metrics.gt_markings.push_back(result);
    metrics.gt_visible += g.visible_frames > 0 ? 1 : 0;
  }

  // Greedy one-to-one assignment by increasing center distance; a map marking whose
  // nearest in-gate GT marking is taken already is a duplicate of it.
  std::vector<MarkingTarget> targets;
  targets.reserve(gt.markings.size());
  for (const GroundTruthMarking& g : gt.markings) targets.push_back({g.center_map, g.class_id});
  const std::vector<MarkingPair> candidates =
      GatedMarkingPairs(map, targets, options.marking_gate_m);
  std::vector<bool> map_done(map.markings.size(), false);
  for (const MarkingPair& c : candidates) {
    MapMarkingResult& m = metrics.map_markings[c.map_index];
    GroundTruthMarkingResult& g = metrics.gt_markings[c.target_index];
    if (map_done[c.map_index]) continue;
    if (g.matched) continue;
    map_done[c.map_index] = true;
    g.matched = true;
    g.map_id = m.map_id;
    m.verdict = MarkingVerdict::kMatched;
    m.gt_id = g.gt_id;
    const GroundTruthMarking& truth = gt.markings[c.target_index];
    m.center_error_map = m.center_map - truth.center_map;
    m.center_error_m = c.distance_m;
    m.corner_error_m = CornerError(map.markings[c.map_index].corners_map, truth.corners_map);
  }
  for (const MarkingPair& c : candidates) {  // nearest first: each duplicate names its nearest
    MapMarkingResult& m = metrics.map_markings[c.map_index];
    if (map_done[c.map_index] || !metrics.gt_markings[c.target_index].matched) continue;
    map_done[c.map_index] = true;
    m.verdict = MarkingVerdict::kDuplicate;
    m.gt_id = metrics.gt_markings[c.target_index].gt_id;
    ++metrics.gt_markings[c.target_index].duplicates;
  }

  std::vector<double> center_errors, corner_errors, complete_center_errors;
  Eigen::Vector3d abs_sum = Eigen::Vector3d::Zero(), signed_sum = Eigen::Vector3d::Zero();
  for (const MapMarkingResult& m : metrics.map_markings) {
    if (m.verdict == MarkingVerdict::kDuplicate) ++metrics.duplicates;
    if (m.verdict != MarkingVerdict::kMatched) {
      ++metrics.unmatched_map;
      continue;
    }
    ++metrics.matched;
    if (m.complete) {
      complete_center_errors.push_back(m.center_error_m);
    } else {
      ++metrics.matched_incomplete;
    }
    center_errors.push_back(m.center_error_m);
    corner_errors.push_back(m.corner_error_m);
    abs_sum += m.center_error_map.cwiseAbs();
    signed_sum += m.center_error_map;
  }
  for (const GroundTruthMarkingResult& g : metrics.gt_markings) {
    metrics.matched_visible += g.matched && g.visible_frames > 0 ? 1 : 0;
  }
  metrics.center_error_m = Summarize(center_errors);
  metrics.center_error_complete_m = Summarize(complete_center_errors);
  metrics.corner_error_m = Summarize(corner_errors);
  if (metrics.matched > 0) {
    metrics.mean_abs_error_xyz_m = abs_sum / metrics.matched;
    metrics.signed_mean_error_xyz_m = signed_sum / metrics.matched;
  }
  if (metrics.gt_visible > 0) {
    metrics.recall = static_cast<double>(metrics.matched_visible) / metrics.gt_visible;
  }
  if (metrics.map_total > 0) {
    metrics.precision = static_cast<double>(metrics.matched) / metrics.map_total;
  }
  return metrics;
}

StorageMetrics EvaluateStorage(const VectorMap& map, const EvaluationOptions& options) {
  StorageMetrics storage;
  storage.map_bytes_from_file = options.map_bytes >= 0;
  // Without a file size, the size the map would have on disk (SaveVectorMapJson's layout:
  // dump(1) plus a newline).
  storage.map_bytes = storage.map_bytes_from_file
                          ? options.map_bytes
                          : static_cast<std::int64_t>(VectorMapToJson(map).dump(1).size() + 1);
  double length_m = 0.0;
  for (const MapLane& lane : map.lanes) {
    storage.control_points += static_cast<int>(lane.control_points_map.size());
    length_m += CatmullRomSpline(lane.control_points_map).Length();
  }
  storage.markings = static_cast<int>(map.markings.size());
  storage.lane_km = length_m / 1000.0;
  if (storage.lane_km > 0.0) {
    storage.map_bytes_per_km = storage.map_bytes / storage.lane_km;
    storage.control_points_per_km = storage.control_points / storage.lane_km;
  }
  return storage;
}

Metrics EvaluateMap(const VectorMap& map, const GroundTruth& gt, const EvaluationOptions& options) {
  Metrics metrics;
  metrics.options = options;
  metrics.markings = EvaluateMarkings(map, gt, options);
  metrics.lanes = EvaluateLanes(map, gt, options);
  metrics.lanelets = EvaluateLanelets(map, gt, options);
  metrics.extrinsic = EvaluateExtrinsic(map, gt, options);
  metrics.poses = EvaluatePoses(map, gt, options);
  metrics.storage = EvaluateStorage(map, options);
  metrics.ceiling = EvaluateViewCeiling(gt, options);
  metrics.seen_parts = EvaluateSeenParts(map, gt, metrics.ceiling, options);
  return metrics;
}

}  // namespace ipm_road_mapper
