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

}  // namespace

std::optional<PathBridge> BridgeAlongPath(const LaneElement& first, const LaneElement& second,
                                          const std::vector<FrameRecord>& frames,
                                          const FrameSpan& span, double max_gap_m, double spacing_m,
                                          double inset_m) {
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
  const Eigen::Vector3d end = cf[cf.size() - 2], start = cs[1];
  const auto a = PlaceOnPath(path, s_at, end.head<2>());
  const auto b = PlaceOnPath(path, s_at, start.head<2>());
  if (!a || !b) return std::nullopt;
  PathBridge bridge;
  bridge.gap_m = b->s - a->s;
  bridge.offset_change_m = b->offset - a->offset;
  if (bridge.gap_m <= 0.0 || bridge.gap_m > max_gap_m ||
      LaneEndDirection(cf, true, kEndDirectionLengthM).dot(a->tangent) < kMinAlongPathCos ||
      LaneEndDirection(cs, false, kEndDirectionLengthM).dot(b->tangent) < kMinAlongPathCos) {
    return std::nullopt;
  }
  for (double s = a->s + inset_m; s <= b->s - inset_m + 1e-9; s += spacing_m) {
    const double t = (s - a->s) / bridge.gap_m;
    const Eigen::Vector2d p = OffsetPoint(path, s_at, s, a->offset + t * bridge.offset_change_m);
    bridge.points.emplace_back(p.x(), p.y(), (1.0 - t) * end.z() + t * start.z());
  }
  return bridge;
}

}  // namespace ipm_road_mapper
