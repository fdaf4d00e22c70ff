// The view's ceiling (eval/view_ceiling.h): which parts of the GT lanes and markings any
// frame of the drive saw, and what a map of exactly those parts would score.
#include <algorithm>
#include <cmath>
#include <numeric>

#include "ipm_road_mapper/core/geometry/pinhole_camera.h"
#include "ipm_road_mapper/core/mapper/frame_index.h"
#include "ipm_road_mapper/eval/evaluation.h"
#include "ipm_road_mapper/eval/view_ceiling.h"

namespace ipm_road_mapper {
namespace {

// Lane points are looked up in runs of at most this many consecutive points within
// kLaneChunkRadiusM of the run's first (one frame query each).
constexpr std::size_t kLaneChunkPoints = 50;
constexpr double kLaneChunkRadiusM = 5.0;
// Most samples of one marking: a larger one is sampled more coarsely.
constexpr double kMaxMarkingSamples = 1e5;
// A GT marking with a corner farther than this from its center (no painted marking has one)
// is not looked for: a hostile ground truth stays cheap.
constexpr double kMaxMarkingRadiusM = 200.0;
// Cell side of the index over the frames' true positions.
constexpr double kFrameCellM = 10.0;

// Every frame of the drive, ready to tell whether it sees a map point.
class DriveViews {
 public:
  DriveViews(const GroundTruth& gt, double view_range_m)
      : camera_(gt.camera), range_m_(view_range_m), index_(kFrameCellM) {
    const Eigen::Isometry3d T_cam_base = gt.T_base_cam_true.inverse();
    for (std::size_t i = 0; i < gt.frames.size(); ++i) {
      const Eigen::Isometry3d& T_map_base = gt.frames[i].T_map_base_true;
      T_base_map_.push_back(T_map_base.inverse());
      T_cam_map_.push_back(T_cam_base * T_base_map_.back());
      index_.Set(i, T_map_base.translation());
    }
  }

  // The frames that may see a point within radius_m of p_map.
  std::vector<std::size_t> Near(const Eigen::Vector3d& p_map, double radius_m) const {
    return index_.Within(p_map, range_m_ + radius_m);
  }

  // True when one of `frames` images p_map within the range.
  bool Sees(const std::vector<std::size_t>& frames, const Eigen::Vector3d& p_map) const {
    for (std::size_t f : frames) {
      if ((T_base_map_[f] * p_map).head<2>().norm() > range_m_) continue;
      Eigen::Vector2d uv;
      if (camera_.Project(Eigen::Vector3d(T_cam_map_[f] * p_map), &uv) && camera_.InImage(uv)) {
        return true;
      }
    }
    return false;
  }

 private:
  PinholeCamera camera_;
  double range_m_;
  FrameIndex index_;
  std::vector<Eigen::Isometry3d> T_base_map_, T_cam_map_;
};

ViewCeilingLane LaneCeiling(const GroundTruthLane& lane, const DriveViews& views,
                            double match_fraction) {
  ViewCeilingLane result;
  result.gt_id = lane.id;
  const std::vector<Eigen::Vector3d>& points = lane.points_map;
  if (points.empty()) return result;
  std::size_t seen = 0;
  for (std::size_t begin = 0, end = 0; begin < points.size(); begin = end) {
    end = begin + 1;
    while (end < points.size() && end - begin < kLaneChunkPoints &&
           (points[end] - points[begin]).head<2>().norm() <= kLaneChunkRadiusM) {
      ++end;
    }
    Eigen::Vector3d center = Eigen::Vector3d::Zero();
    for (std::size_t k = begin; k < end; ++k) center += points[k];
    center /= static_cast<double>(end - begin);
    double radius_m = 0.0;
    for (std::size_t k = begin; k < end; ++k) {
      radius_m = std::max(radius_m, (points[k] - center).head<2>().norm());
    }
    const std::vector<std::size_t> frames = views.Near(center, radius_m);
    for (std::size_t k = begin; k < end; ++k) seen += views.Sees(frames, points[k]) ? 1 : 0;
  }
  result.in_view_fraction = static_cast<double>(seen) / points.size();
  result.reachable = result.in_view_fraction >= match_fraction;
  return result;
}

// The point at (s, t) of the quadrilateral c0 c1 c2 c3: s runs c0 -> c1, t runs c0 -> c3.
Eigen::Vector3d Bilinear(const std::array<Eigen::Vector3d, 4>& c, double s, double t) {
  return (1.0 - t) * ((1.0 - s) * c[0] + s * c[1]) + t * ((1.0 - s) * c[3] + s * c[2]);
}

int SamplesAlong(double length_m, double spacing_m) {
  return 1 + static_cast<int>(std::max(1.0, std::ceil(length_m / spacing_m)));
}

ViewCeilingMarking MarkingCeiling(const GroundTruthMarking& marking, const DriveViews& views,
                                  const EvaluationOptions& options) {
  ViewCeilingMarking result;
  result.gt_id = marking.id;
  result.visible_frames = marking.visible_frames;
  result.in_view_center_offset_m = kNoValue;
  result.in_view_center_map = Eigen::Vector3d::Constant(kNoValue);
  const std::array<Eigen::Vector3d, 4>& c = marking.corners_map;
  double radius_m = 0.0;
  for (const Eigen::Vector3d& corner : c) {
    radius_m = std::max(radius_m, (corner - marking.center_map).head<2>().norm());
  }
  if (!(radius_m <= kMaxMarkingRadiusM)) return result;
  const double length_s = std::max((c[1] - c[0]).norm(), (c[2] - c[3]).norm());
  const double length_t = std::max((c[3] - c[0]).norm(), (c[2] - c[1]).norm());
  const double spacing_m = std::max({options.view_marking_sample_spacing_m, 1e-3,
                                     std::sqrt(length_s * length_t / kMaxMarkingSamples)});
  const int ns = SamplesAlong(length_s, spacing_m);
  const int nt = SamplesAlong(length_t, spacing_m);
  const std::vector<std::size_t> frames = views.Near(marking.center_map, radius_m);
  double s_min = 1.0, s_max = 0.0, t_min = 1.0, t_max = 0.0;
  int seen = 0;
  for (int i = 0; i < ns; ++i) {
    const double s = static_cast<double>(i) / (ns - 1);
    for (int j = 0; j < nt; ++j) {
      const double t = static_cast<double>(j) / (nt - 1);
      if (!views.Sees(frames, Bilinear(c, s, t))) continue;
      ++seen;
      s_min = std::min(s_min, s);
      s_max = std::max(s_max, s);
      t_min = std::min(t_min, t);
      t_max = std::max(t_max, t);
    }
  }
  result.in_view_fraction = static_cast<double>(seen) / (ns * nt);
  if (seen > 0) {
    const Eigen::Vector3d center = Bilinear(c, 0.5 * (s_min + s_max), 0.5 * (t_min + t_max));
    result.in_view_center_map = center;
    result.in_view_center_offset_m = (center - marking.center_map).norm();
    result.reachable =
        marking.visible_frames > 0 && result.in_view_center_offset_m <= options.marking_gate_m;
  }
  return result;
}

}  // namespace

ViewCeilingMetrics EvaluateViewCeiling(const GroundTruth& gt, const EvaluationOptions& options) {
  ViewCeilingMetrics metrics;
  metrics.view_range_m = options.view_range_m;
  metrics.lane_recall = metrics.lane_f1 = metrics.marking_recall = kNoValue;
  const DriveViews views(gt, options.view_range_m);
  for (const GroundTruthLane& lane : gt.lanes) {
    metrics.lanes.push_back(LaneCeiling(lane, views, options.lane_match_fraction));
    metrics.lanes_reachable += metrics.lanes.back().reachable ? 1 : 0;
  }
  metrics.lanes_total = static_cast<int>(gt.lanes.size());
  if (metrics.lanes_total > 0) {
    metrics.lane_recall = static_cast<double>(metrics.lanes_reachable) / metrics.lanes_total;
    metrics.lane_f1 = 2.0 * metrics.lane_recall / (1.0 + metrics.lane_recall);
  }
  for (const GroundTruthMarking& marking : gt.markings) {
    metrics.markings.push_back(MarkingCeiling(marking, views, options));
    metrics.markings_visible += marking.visible_frames > 0 ? 1 : 0;
    metrics.markings_reachable += metrics.markings.back().reachable ? 1 : 0;
  }
  if (metrics.markings_visible > 0) {
    metrics.marking_recall =
        static_cast<double>(metrics.markings_reachable) / metrics.markings_visible;
  }
  return metrics;
}

SeenPartMetrics EvaluateSeenParts(const VectorMap& map, const GroundTruth& gt,
                                  const ViewCeilingMetrics& ceiling,
                                  const EvaluationOptions& options) {
  SeenPartMetrics metrics;
  metrics.recall = metrics.center_error_mean_m = metrics.center_error_max_m = kNoValue;
  // One target per GT marking the masks hold and some frame saw: its seen part's center.
  std::vector<MarkingTarget> targets;
  for (std::size_t j = 0; j < gt.markings.size() && j < ceiling.markings.size(); ++j) {
    const ViewCeilingMarking& seen = ceiling.markings[j];
    if (seen.visible_frames <= 0 || !seen.in_view_center_map.allFinite()) continue;
    targets.push_back({seen.in_view_center_map, gt.markings[j].class_id});
    SeenPartMarking result;
    result.gt_id = seen.gt_id;
    result.center_error_m = kNoValue;
    metrics.markings.push_back(result);
  }
  // Greedy one-to-one by increasing distance, as EvaluateMarkings.
  std::vector<bool> map_used(map.markings.size(), false);
  std::vector<double> errors;
  for (const MarkingPair& pair : GatedMarkingPairs(map, targets, options.marking_gate_m)) {
    SeenPartMarking& result = metrics.markings[pair.target_index];
    if (map_used[pair.map_index] || result.matched) continue;
    map_used[pair.map_index] = true;
    result.matched = true;
    result.map_id = map.markings[pair.map_index].id;
    result.center_error_m = pair.distance_m;
    errors.push_back(pair.distance_m);
  }
  metrics.gt_seen = static_cast<int>(metrics.markings.size());
  metrics.matched = static_cast<int>(errors.size());
  if (metrics.gt_seen > 0) metrics.recall = static_cast<double>(metrics.matched) / metrics.gt_seen;
  if (!errors.empty()) {
    metrics.center_error_mean_m =
        std::accumulate(errors.begin(), errors.end(), 0.0) / static_cast<double>(errors.size());
    metrics.center_error_max_m = *std::max_element(errors.begin(), errors.end());
  }
  return metrics;
}

}  // namespace ipm_road_mapper
