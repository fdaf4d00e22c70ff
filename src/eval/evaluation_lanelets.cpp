// Lanelet evaluation (LaneletMetrics in evaluation.h): the lanelets of the map's lines against
// those of the GT lines, both found by core/map/lanelet_pairing.h, compared by centerlines.
#include <cmath>
#include <map>
#include <set>
#include <vector>

#include "ipm_road_mapper/core/io/map_geodesy.h"
#include "ipm_road_mapper/core/map/lanelet_pairing.h"
#include "ipm_road_mapper/core/mapper/frame_index.h"
#include "ipm_road_mapper/eval/evaluation.h"

namespace ipm_road_mapper {
namespace {

// Centerline samples on another centerline must run within this angle of it.
const double kMinDirectionCos = std::cos(30.0 * M_PI / 180.0);

struct CenterSample {
  Eigen::Vector2d p;
  Eigen::Vector2d direction;
  std::size_t lanelet;
};

// Polylines resampled every kLaneSampleSpacing_m, split where consecutive points are more
// than max_link_m apart (a GT line interrupted, at an intersection say, is two lines).
std::vector<std::vector<Eigen::Vector3d>> GroundTruthLines(const GroundTruth& gt,
                                                           double max_link_m) {
  std::vector<std::vector<Eigen::Vector3d>> lines;
  for (const GroundTruthLane& lane : gt.lanes) {
    std::vector<Eigen::Vector3d> piece;
    auto flush = [&] {
      if (piece.size() >= 2) {
        const std::vector<double> arc = ArcLengths(piece);
        std::vector<Eigen::Vector3d> resampled;
        for (double s = 0.0; s < arc.back(); s += kLaneSampleSpacing_m) {
          resampled.push_back(PointAtArcLength(piece, arc, s));
        }
        resampled.push_back(piece.back());
        lines.push_back(std::move(resampled));
      }
      piece.clear();
    };
    for (const Eigen::Vector3d& p : lane.points_map) {
      if (!piece.empty() && (p - piece.back()).head<2>().norm() > max_link_m) flush();
      piece.push_back(p);
    }
    flush();
  }
  return lines;
}

// Centerline samples of every lanelet of `lines` (every kLaneletSampleSpacingM along the
// longer bound); `count` gets the number of lanelets.
std::vector<CenterSample> Centerlines(const std::vector<std::vector<Eigen::Vector3d>>& lines,
                                      std::size_t* count) {
  const LaneletLayout layout = PairLanelets(lines);
  *count = layout.lanelets.size();
  std::vector<std::vector<double>> arcs;
  for (const auto& line : lines) arcs.push_back(ArcLengths(line));
  std::vector<CenterSample> samples;
  for (std::size_t k = 0; k < layout.lanelets.size(); ++k) {
    const LaneletBounds& b = layout.lanelets[k];
    const auto [r0, r1] =
        PieceRange(layout, b.right_line, b.right_piece, arcs[b.right_line].back());
    const auto [l0, l1] = PieceRange(layout, b.left_line, b.left_piece, arcs[b.left_line].back());
    const int n = std::max(
        1, static_cast<int>(std::ceil(std::max(r1 - r0, l1 - l0) / kLaneletSampleSpacingM)));
    std::vector<Eigen::Vector2d> points;
    for (int i = 0; i <= n; ++i) {
      const double f = static_cast<double>(i) / n;
      const Eigen::Vector3d r =
          PointAtArcLength(lines[b.right_line], arcs[b.right_line], r0 + f * (r1 - r0));
      const Eigen::Vector3d l =
          PointAtArcLength(lines[b.left_line], arcs[b.left_line], l0 + f * (l1 - l0));
      points.push_back(0.5 * (r + l).head<2>());
    }
    // One sample per interval, at its middle, with the interval's direction.
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector2d d = points[i + 1] - points[i];
      if (d.norm() < 1e-9) continue;
      samples.push_back({0.5 * (points[i] + points[i + 1]), d.normalized(), k});
    }
  }
  return samples;
}

// The samples of `samples` in a spatial index (the one the mapper keeps of its frames).
FrameIndex IndexOf(const std::vector<CenterSample>& samples, double cell_m) {
  FrameIndex index(cell_m);
  for (std::size_t i = 0; i < samples.size(); ++i) {
    index.Set(i, Eigen::Vector3d(samples[i].p.x(), samples[i].p.y(), 0.0));
  }
  return index;
}

// The samples of `samples` (indexed by `index`) within radius_m of `s` running within 30 deg
// of it.
template <typename Visit>
void ForEachOn(const std::vector<CenterSample>& samples, const FrameIndex& index,
               const CenterSample& s, double radius_m, Visit visit) {
  for (std::size_t i : index.Within(Eigen::Vector3d(s.p.x(), s.p.y(), 0.0), radius_m)) {
    if (samples[i].direction.dot(s.direction) >= kMinDirectionCos) visit(samples[i]);
  }
}

}  // namespace

LaneletMetrics EvaluateLanelets(const VectorMap& map, const GroundTruth& gt,
                                const EvaluationOptions& options) {
  LaneletMetrics metrics;
  std::vector<StampedPose> gt_drive;
  for (const GroundTruthFrame& f : gt.frames) gt_drive.push_back({f.stamp, f.T_map_base_true});
  std::vector<std::vector<Eigen::Vector3d>> gt_lines;
  for (auto& line : GroundTruthLines(gt, options.lane_max_link_m)) {
    gt_lines.push_back(LaneOrientedAlongDrive(std::move(line), gt_drive));
  }
  std::vector<std::vector<Eigen::Vector3d>> map_lines;
  for (const MapLane& lane : map.lanes) {
    std::vector<Eigen::Vector3d> line = LanePolyline(lane, kLaneSampleSpacing_m);
    if (line.size() >= 2)
      map_lines.push_back(LaneOrientedAlongDrive(std::move(line), map.trajectory));
  }
  std::size_t gt_count = 0, map_count = 0;
  const std::vector<CenterSample> gt_samples = Centerlines(gt_lines, &gt_count);
  const std::vector<CenterSample> map_samples = Centerlines(map_lines, &map_count);
  metrics.gt_total = static_cast<int>(gt_count);
  metrics.map_total = static_cast<int>(map_count);
  auto length = [](const std::vector<CenterSample>& samples) {
    return static_cast<double>(samples.size()) * kLaneletSampleSpacingM;
  };
  metrics.gt_length_m = length(gt_samples);
  metrics.map_length_m = length(map_samples);
  const double radius = options.lane_match_distance_m;
  const double cell = std::max(radius, 1e-3);

  // Recall, and per GT lanelet its covered samples and the map lanelets lying on it.
  const FrameIndex map_index = IndexOf(map_samples, cell);
  std::vector<std::size_t> covered(gt_count, 0), total(gt_count, 0);
  std::vector<std::map<std::size_t, std::size_t>> on(gt_count);  // map lanelet -> samples
  std::size_t gt_on = 0;
  for (const CenterSample& g : gt_samples) {
    ++total[g.lanelet];
    std::set<std::size_t> here;
    ForEachOn(map_samples, map_index, g, radius,
              [&](const CenterSample& m) { here.insert(m.lanelet); });
    if (here.empty()) continue;
    ++gt_on;
    ++covered[g.lanelet];
    for (std::size_t m : here) ++on[g.lanelet][m];
  }
  if (!gt_samples.empty()) {
    metrics.recall = static_cast<double>(gt_on) / static_cast<double>(gt_samples.size());
  }
  // Precision.
  const FrameIndex gt_index = IndexOf(gt_samples, cell);
  std::size_t map_on = 0;
  for (const CenterSample& m : map_samples) {
    bool near = false;
    ForEachOn(gt_samples, gt_index, m, radius, [&](const CenterSample&) { near = true; });
    if (near) ++map_on;
  }
  if (!map_samples.empty()) {
    metrics.precision = static_cast<double>(map_on) / static_cast<double>(map_samples.size());
  }
  // Pieces per covered GT lanelet.
  double pieces = 0.0;
  int covered_lanelets = 0;
  for (std::size_t k = 0; k < gt_count; ++k) {
    if (total[k] == 0 || static_cast<double>(covered[k]) <
                             options.lane_match_fraction * static_cast<double>(total[k])) {
      continue;
    }
    int n = 0;
    for (const auto& [m, samples] : on[k]) {
      if (static_cast<double>(samples) * kLaneletSampleSpacingM >= options.lane_cover_min_length_m)
        ++n;
    }
    pieces += n;
    ++covered_lanelets;
  }
  if (covered_lanelets > 0) metrics.lanelets_per_covered_gt_lanelet = pieces / covered_lanelets;
  return metrics;
}

}  // namespace ipm_road_mapper
