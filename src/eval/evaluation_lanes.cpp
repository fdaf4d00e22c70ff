// Lane evaluation: APE of the mapped splines against the GT lane polylines, and the lane F1
// of the MonoLaneMapping convention (docs/file_formats.md, "Metrics JSON").
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <stdexcept>

#include "ipm_road_mapper/core/geometry/catmull_rom_spline.h"
#include "ipm_road_mapper/core/map/lane_samples.h"
#include "ipm_road_mapper/eval/evaluation.h"

namespace ipm_road_mapper {
namespace {

// Closest point to q on the segment [a, b] (a == b allowed).
Eigen::Vector3d ClosestOnSegment(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                 const Eigen::Vector3d& q) {
  const Eigen::Vector3d ab = b - a;
  const double length2 = ab.squaredNorm();
  if (length2 <= 0.0) return a;
  const double t = std::clamp((q - a).dot(ab) / length2, 0.0, 1.0);
  return a + t * ab;
}

// Length of a polyline counting only the joined pieces (gaps > max_link_m are skipped).
double PolylineLength(const std::vector<Eigen::Vector3d>& points, double max_link_m) {
  double length = 0.0;
  for (std::size_t k = 1; k < points.size(); ++k) {
    const double step = (points[k] - points[k - 1]).norm();
    if (step <= max_link_m) length += step;
  }
  return length;
}

// F1 from precision and recall; a map without lanes has precision 0 against a non-empty GT.
double F1Score(double precision, double recall) {
  if (std::isnan(recall)) return kNoValue;
  const double p = std::isnan(precision) ? 0.0 : precision;
  return p + recall > 0.0 ? 2.0 * p * recall / (p + recall) : 0.0;
}

// Refuses a map whose lanes, sampled at options.lane_sample_spacing_m, exceed
// options.max_lane_samples (a hostile map with a control point 1e6 m away would otherwise
// cost 10^7 samples and as many nearest-point queries per lane).
void CheckLaneSampleBudget(const VectorMap& map, const EvaluationOptions& options) {
  double length_m = 0.0;
  for (std::size_t i = 0; i < map.lanes.size(); ++i) {
    const std::vector<Eigen::Vector3d>& points = map.lanes[i].control_points_map;
    if (points.size() < 4) continue;  // the spline constructor reports it below
    length_m += CatmullRomSpline(points).Length();
    const double samples = length_m / options.lane_sample_spacing_m;
    if (!(samples <= options.max_lane_samples)) {
      char message[200];
      std::snprintf(message, sizeof(message),
                    "map lanes[%zu]: the lanes up to here are %.3g m long, %.3g samples at %g m, "
                    "beyond the evaluator's budget of %.3g samples",
                    i, length_m, samples, options.lane_sample_spacing_m, options.max_lane_samples);
      throw MapFormatError(message);
    }
  }
}

}  // namespace

PolylineDistanceIndex::PolylineDistanceIndex(
    const std::vector<std::vector<Eigen::Vector3d>>& polylines, double max_link_m) {
  for (std::size_t i = 0; i < polylines.size(); ++i) {
    const std::vector<Eigen::Vector3d>& points = polylines[i];
    const int polyline = static_cast<int>(i);
    bool previous_joined = false;  // whether points[k] ends a segment added already
    for (std::size_t k = 0; k < points.size(); ++k) {
      const bool next_joined =
          k + 1 < points.size() && (points[k + 1] - points[k]).norm() <= max_link_m;
      if (next_joined) {
        segments_.push_back(
            {points[k], points[k + 1], 0.5 * (points[k] + points[k + 1]), polyline});
        max_half_length_m_ = std::max(max_half_length_m_, 0.5 * (points[k + 1] - points[k]).norm());
      } else if (!previous_joined) {
        segments_.push_back({points[k], points[k], points[k], polyline});  // isolated point
      }
      previous_joined = next_joined;
    }
  }
  split_axis_.assign(segments_.size(), 0);
  Build(0, static_cast<int>(segments_.size()));
}

void PolylineDistanceIndex::Build(int begin, int end) {
  if (end - begin <= 1) return;
  Eigen::Vector3d low = segments_[begin].mid, high = low;
  for (int k = begin; k < end; ++k) {
    low = low.cwiseMin(segments_[k].mid);
    high = high.cwiseMax(segments_[k].mid);
  }
  int axis = 0;
  (high - low).maxCoeff(&axis);
  const int middle = begin + (end - begin) / 2;
  std::nth_element(
      segments_.begin() + begin, segments_.begin() + middle, segments_.begin() + end,
      [axis](const Segment& a, const Segment& b) { return a.mid[axis] < b.mid[axis]; });
  split_axis_[middle] = axis;
  Build(begin, middle);
  Build(middle + 1, end);
}

void PolylineDistanceIndex::Search(int begin, int end, const Eigen::Vector3d& query,
                                   Nearest* best) const {
  if (begin >= end) return;
  const int middle = begin + (end - begin) / 2;
  const Segment& segment = segments_[middle];
  const Eigen::Vector3d closest = ClosestOnSegment(segment.a, segment.b, query);
  const double distance = (closest - query).norm();
  if (distance < best->distance_m) *best = {distance, segment.polyline, closest};
  if (end - begin == 1) return;
  // Every segment on the far side has its midpoint beyond the splitting plane, so it is at
  // least (plane distance - max half length) away.
  const int axis = split_axis_[middle];
  const double plane_distance = query[axis] - segment.mid[axis];
  const bool left_first = plane_distance < 0.0;
  Search(left_first ? begin : middle + 1, left_first ? middle : end, query, best);
  if (std::abs(plane_distance) - max_half_length_m_ < best->distance_m) {
    Search(left_first ? middle + 1 : begin, left_first ? end : middle, query, best);
  }
}

PolylineDistanceIndex::Nearest PolylineDistanceIndex::Query(const Eigen::Vector3d& query) const {
  Nearest best;
  Search(0, static_cast<int>(segments_.size()), query, &best);
  return best;
}

LaneMetrics EvaluateLanes(const VectorMap& map, const GroundTruth& gt,
                          const EvaluationOptions& options) {
  LaneMetrics metrics;
  std::vector<std::vector<Eigen::Vector3d>> gt_polylines;
  for (const GroundTruthLane& lane : gt.lanes) gt_polylines.push_back(lane.points_map);
  const PolylineDistanceIndex gt_index(gt_polylines, options.lane_max_link_m);
  const bool have_gt = !gt.lanes.empty();

  // Mapped splines -> GT: per-sample errors, precision, and which GT lane each sample is on.
  std::vector<double> errors, errors_xy, errors_z, errors_unmeasured, errors_measured;
  std::vector<std::vector<Eigen::Vector3d>> map_samples;
  std::vector<std::map<std::uint64_t, int>> on_samples_per_gt(gt.lanes.size());
  CheckLaneSampleBudget(map, options);
  for (const MapLane& lane : map.lanes) {
    std::unique_ptr<CatmullRomSpline> spline;
    try {
      spline = std::make_unique<CatmullRomSpline>(lane.control_points_map);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("lane " + std::to_string(lane.id) + ": " + e.what());
    }
    MapLaneResult result;
    result.map_id = lane.id;
    result.class_name = lane.class_name;
    result.control_points = static_cast<int>(lane.control_points_map.size());
    result.length_m = spline->Length();
    LaneSamples samples = SampleLane(lane.control_points_map, UnmeasuredPointFlags(lane),
                                     options.lane_sample_spacing_m);
    for (const bool unmeasured : samples.unmeasured) {
      if (unmeasured) metrics.unmeasured_length_m += options.lane_sample_spacing_m;
    }
    map_samples.push_back(std::move(samples.points));
    if (have_gt) {
      std::vector<double> lane_errors;
      std::vector<int> nearest_count(gt.lanes.size(), 0);
      int on_gt = 0;
      for (std::size_t k = 0; k < map_samples.back().size(); ++k) {
        const Eigen::Vector3d& sample = map_samples.back()[k];
        const PolylineDistanceIndex::Nearest nearest = gt_index.Query(sample);
        const Eigen::Vector3d error = sample - nearest.point;
        lane_errors.push_back(nearest.distance_m);
        (samples.unmeasured[k] ? errors_unmeasured : errors_measured).push_back(nearest.distance_m);
        errors_xy.push_back(error.head<2>().norm());
        errors_z.push_back(std::abs(error.z()));
        ++nearest_count[nearest.polyline];
        if (nearest.distance_m <= options.lane_match_distance_m) {
          ++on_gt;
          ++on_samples_per_gt[nearest.polyline][lane.id];
        }
      }
      const auto most = std::max_element(nearest_count.begin(), nearest_count.end());
      result.nearest_gt_id = gt.lanes[most - nearest_count.begin()].id;
      result.fraction_on_gt =
          lane_errors.empty() ? 0.0 : static_cast<double>(on_gt) / lane_errors.size();
      result.true_positive = result.fraction_on_gt >= options.lane_match_fraction;
      errors.insert(errors.end(), lane_errors.begin(), lane_errors.end());
      result.error_m = Summarize(std::move(lane_errors));
    }
    metrics.mapped_length_m += result.length_m;
    metrics.map_true_positive += result.true_positive ? 1 : 0;
    metrics.map_lanes.push_back(std::move(result));
  }
  metrics.map_total = static_cast<int>(map.lanes.size());
  metrics.error_m = Summarize(errors);
  metrics.error_unmeasured_m = Summarize(std::move(errors_unmeasured));
  metrics.error_measured_m = Summarize(std::move(errors_measured));
  metrics.error_xy_mean_m = Summarize(errors_xy).mean;
  metrics.error_z_mean_m = Summarize(errors_z).mean;

  // GT lanes -> map: coverage, recall and the splines lying on each GT lane.
  const PolylineDistanceIndex map_index(map_samples, options.lane_max_link_m);
  int covering_splines = 0;  // summed over matched GT lanes
  for (std::size_t g = 0; g < gt.lanes.size(); ++g) {
    const GroundTruthLane& gt_lane = gt.lanes[g];
    GroundTruthLaneResult result;
    result.gt_id = gt_lane.id;
    result.class_name = gt_lane.class_name;
    result.length_m = PolylineLength(gt_lane.points_map, options.lane_max_link_m);
    int covered = 0;
    if (!map_samples.empty()) {
      for (const Eigen::Vector3d& point : gt_lane.points_map) {
        covered += map_index.Query(point).distance_m <= options.lane_match_distance_m ? 1 : 0;
      }
    }
    result.coverage = static_cast<double>(covered) / gt_lane.points_map.size();
    result.matched = result.coverage >= options.lane_match_fraction;
    for (const auto& [map_id, samples] : on_samples_per_gt[g]) {
      if (samples * options.lane_sample_spacing_m >= options.lane_cover_min_length_m) {
        result.covering_map_ids.push_back(map_id);
      }
    }
    if (result.matched) {
      ++metrics.gt_matched;
      covering_splines += static_cast<int>(result.covering_map_ids.size());
    }
    metrics.gt_lanes.push_back(std::move(result));
  }
  if (metrics.gt_matched > 0) {
    metrics.splines_per_matched_gt_lane =
        static_cast<double>(covering_splines) / metrics.gt_matched;
  }
  metrics.gt_total = static_cast<int>(gt.lanes.size());
  if (metrics.gt_total > 0)
    metrics.recall = static_cast<double>(metrics.gt_matched) / metrics.gt_total;
  if (metrics.map_total > 0 && have_gt) {
    metrics.precision = static_cast<double>(metrics.map_true_positive) / metrics.map_total;
  }
  metrics.f1 = F1Score(metrics.precision, metrics.recall);
  return metrics;
}

}  // namespace ipm_road_mapper
