#include "ipm_road_mapper/core/mapper/lane_path_bridge.h"

#include <algorithm>
#include <cmath>

#include "ipm_road_mapper/core/mapper/lane_join.h"

namespace ipm_road_mapper {
namespace {

// Path vertices closer than this to the previous one are skipped (a standstill's frames).
constexpr double kMinVertexSpacingM = 0.5;
// A span of more frames than this is no gap driven once (e.g. two passes): no bridge.
constexpr std::size_t kMaxSpanFrames = 6000;
// An end runs along the path when its direction is within this of the path's (30 deg, the
// join's kMinDirectionCos).
constexpr double kMinAlongPathCos = 0.87;
// An end's direction: over its last this many meters of control points (LaneEndDirection).
constexpr double kEndDirectionLengthM = 6.0;

struct PathPlace {
  double s = 0.0;       // arc length along the path
  double offset = 0.0;  // signed lateral offset, left positive
  Eigen::Vector2d tangent = Eigen::Vector2d::UnitX();
};

// Where `p` lies beside the polyline: its foot on the nearest segment. Nullopt when the
// foot is before the path's start or past its end (the path does not reach beside p).
std::optional<PathPlace> PlaceOnPath(const std::vector<Eigen::Vector2d>& path,
                                     const std::vector<double>& s_at, const Eigen::Vector2d& p) {
  double best = 1e18;
  std::optional<PathPlace> place;
  for (std::size_t i = 0; i + 1 < path.size(); ++i) {
    const Eigen::Vector2d v = path[i + 1] - path[i];
    const double length = v.norm();
    const Eigen::Vector2d u = v / length;
    const double along = (p - path[i]).dot(u);
    if ((i == 0 && along < 0.0) || (i + 2 == path.size() && along > length)) continue;
    const double t = std::clamp(along, 0.0, length);
    const double distance = (p - (path[i] + t * u)).norm();
    if (distance < best) {
      best = distance;
      const Eigen::Vector2d d = p - path[i];
      place = PathPlace{s_at[i] + t, u.x() * d.y() - u.y() * d.x(), u};
    }
  }
  return place;
}

// The point at arc length s along the path, `offset` to its left.
Eigen::Vector2d OffsetPoint(const std::vector<Eigen::Vector2d>& path,
                            const std::vector<double>& s_at, double s, double offset) {
  std::size_t i = std::upper_bound(s_at.begin(), s_at.end(), s) - s_at.begin();
  i = std::clamp<std::size_t>(i, 1, path.size() - 1) - 1;
  const Eigen::Vector2d u = (path[i + 1] - path[i]).normalized();
  return path[i] + (s - s_at[i]) * u + offset * Eigen::Vector2d(-u.y(), u.x());
}

// An end's offset from the path: the median of its control points' offsets over its last
// `end_length_m` (the join's end models' length). The end's last control points are the ones
// the fewest points shaped: where a line curves out of the view at the image's edge they can
// lie a meter off (urban with its vehicles labelled: the last two 0.38 and 1.30 m off the
// line, the five before them within 0.06 m). Nullopt when none of them lies beside the path.
std::optional<double> EndOffset(const std::vector<Eigen::Vector3d>& cps, bool at_end,
                                double end_length_m, const std::vector<Eigen::Vector2d>& path,
                                const std::vector<double>& s_at) {
  const std::size_t n = cps.size() - 2;  // real control points 1..n
  std::vector<double> offsets;
  double length = 0.0;
  for (std::size_t k = 0; k < n && length <= end_length_m; ++k) {
    const std::size_t i = at_end ? n - k : 1 + k;
    if (k > 0) length += (cps[i] - cps[at_end ? i + 1 : i - 1]).head<2>().norm();
    if (length > end_length_m) break;
    if (const auto place = PlaceOnPath(path, s_at, cps[i].head<2>())) {
      offsets.push_back(place->offset);
    }
  }
  if (offsets.empty()) return std::nullopt;
  const std::size_t mid = offsets.size() / 2;
  std::nth_element(offsets.begin(), offsets.begin() + mid, offsets.end());
  if (offsets.size() % 2 == 1) return offsets[mid];
  const double upper = offsets[mid];
  return 0.5 * (upper + *std::max_element(offsets.begin(), offsets.begin() + mid));
}

// How many of the end's control points (from the last inward) lie off `offset` by more than
// `max_deviation_m`, or not beside the path; at least two real ones are kept.
std::size_t OffEndCount(const std::vector<Eigen::Vector3d>& cps, bool at_end, double offset,
                        double max_deviation_m, const std::vector<Eigen::Vector2d>& path,
                        const std::vector<double>& s_at) {
  const std::size_t n = cps.size() - 2;
  std::size_t count = 0;
  while (count + 3 <= n) {  // dropping one more keeps two
    const std::size_t i = at_end ? n - count : 1 + count;
    const auto place = PlaceOnPath(path, s_at, cps[i].head<2>());
    if (place && std::abs(place->offset - offset) <= max_deviation_m) break;
    ++count;
  }
  return count;
}

// `cps` without `count` real control points at its end (or start), phantoms re-made.
std::vector<Eigen::Vector3d> Trimmed(const std::vector<Eigen::Vector3d>& cps, bool at_end,
                                     std::size_t count) {
  std::vector<Eigen::Vector3d> out(cps.begin() + (at_end ? 1 : 1 + count),
                                   cps.end() - (at_end ? 1 + count : 1));
  out.insert(out.begin(), 2.0 * out[0] - out[1]);
  out.push_back(2.0 * out[out.size() - 1] - out[out.size() - 2]);
  return out;
}

}  // namespace

std::optional<PathBridge> BridgeAlongPath(const LaneElement& first, const LaneElement& second,
                                          const std::vector<FrameRecord>& frames,
                                          const FrameSpan& span, double max_gap_m, double spacing_m,
                                          double inset_m, double end_length_m,
                                          double max_end_deviation_m) {
  const std::vector<Eigen::Vector3d>& cf = first.control_points_map;
  const std::vector<Eigen::Vector3d>& cs = second.control_points_map;
  const std::size_t to = std::min(span.to, frames.size());
  if (cf.size() < 4 || cs.size() < 4 || span.from >= to || to - span.from > kMaxSpanFrames ||
      spacing_m <= 0.0) {
    return std::nullopt;
  }
  std::vector<Eigen::Vector2d> path;
  std::vector<double> s_at;
  for (std::size_t i = span.from; i < to; ++i) {
    const Eigen::Vector2d p = frames[i].T_map_base.translation().head<2>();
    if (!path.empty() && (p - path.back()).norm() < kMinVertexSpacingM) continue;
    s_at.push_back(path.empty() ? 0.0 : s_at.back() + (p - path.back()).norm());
    path.push_back(p);
  }
  if (path.size() < 2) return std::nullopt;
  const auto a_offset = EndOffset(cf, true, end_length_m, path, s_at);
  const auto b_offset = EndOffset(cs, false, end_length_m, path, s_at);
  if (!a_offset || !b_offset) return std::nullopt;
  // The ends' control points off their end's offset are replaced by the bridge.
  PathBridge bridge;
  bridge.first_end_dropped = OffEndCount(cf, true, *a_offset, max_end_deviation_m, path, s_at);
  bridge.second_start_dropped = OffEndCount(cs, false, *b_offset, max_end_deviation_m, path, s_at);
  const std::vector<Eigen::Vector3d> kf = Trimmed(cf, true, bridge.first_end_dropped);
  const std::vector<Eigen::Vector3d> ks = Trimmed(cs, false, bridge.second_start_dropped);
  const Eigen::Vector3d end = kf[kf.size() - 2], start = ks[1];
  const auto a = PlaceOnPath(path, s_at, end.head<2>());
  const auto b = PlaceOnPath(path, s_at, start.head<2>());
  // Where the data ended (the dropped control points had data): the gap no frame may have seen.
  const auto data_a = PlaceOnPath(path, s_at, cf[cf.size() - 2].head<2>());
  const auto data_b = PlaceOnPath(path, s_at, cs[1].head<2>());
  if (!a || !b || !data_a || !data_b) return std::nullopt;
  bridge.gap_m = b->s - a->s;
  bridge.offset_change_m = *b_offset - *a_offset;
  if (bridge.gap_m <= 0.0 || bridge.gap_m > max_gap_m ||
      LaneEndDirection(kf, true, kEndDirectionLengthM).dot(a->tangent) < kMinAlongPathCos ||
      LaneEndDirection(ks, false, kEndDirectionLengthM).dot(b->tangent) < kMinAlongPathCos) {
    return std::nullopt;
  }
  for (double s = a->s + inset_m; s <= b->s - inset_m + 1e-9; s += spacing_m) {
    const double t = (s - a->s) / bridge.gap_m;
    const Eigen::Vector2d p = OffsetPoint(path, s_at, s, *a_offset + t * bridge.offset_change_m);
    bridge.points.emplace_back(p.x(), p.y(), (1.0 - t) * end.z() + t * start.z());
    if (s >= data_a->s && s <= data_b->s) bridge.unseen_points.push_back(bridge.points.back());
  }
  return bridge;
}

}  // namespace ipm_road_mapper
