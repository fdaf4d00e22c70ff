#include "ipm_road_mapper/core/map/lanelet_pairing.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <unordered_map>

#include "ipm_road_mapper/core/geometry/grid_cell.h"

namespace ipm_road_mapper {
namespace {

// Beyond this along a line's end, the nearest point of the line is its end: no neighbour.
constexpr double kPastEndM = 0.25;
// Lines closer than this side by side are the same line seen twice, not neighbours.
constexpr double kSameLineM = 0.05;
// Passes of carrying cuts across lanes; a cut crosses one lane per pass.
constexpr int kMaxCutPasses = 16;

// Unit x-y direction of a polyline at sample k (central difference, one-sided at the ends).
Eigen::Vector2d DirectionAt(const std::vector<Eigen::Vector3d>& line, std::size_t k) {
  const std::size_t a = k > 0 ? k - 1 : 0;
  const std::size_t b = std::min(k + 1, line.size() - 1);
  const Eigen::Vector2d d = (line[b] - line[a]).head<2>();
  return d.norm() > 1e-9 ? Eigen::Vector2d(d.normalized()) : Eigen::Vector2d::Zero();
}

double Cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

// The segments of every line in a uniform grid (cells kMaxLaneWidthM wide), for the nearest
// segments of other lines within a lane width.
class SegmentGrid {
 public:
  struct Segment {
    std::size_t line, index;  // from sample index to index + 1
  };

  explicit SegmentGrid(const std::vector<std::vector<Eigen::Vector3d>>& lines) {
    for (std::size_t l = 0; l < lines.size(); ++l) {
      for (std::size_t k = 0; k + 1 < lines[l].size(); ++k) {
        const Eigen::Vector2d a = lines[l][k].head<2>(), b = lines[l][k + 1].head<2>();
        if (!((b - a).norm() <= kMaxIndexedSegmentM)) continue;
        const auto [x0, y0] = Cell(a.cwiseMin(b));
        const auto [x1, y1] = Cell(a.cwiseMax(b));
        for (std::int64_t x = x0; x <= x1; ++x) {
          for (std::int64_t y = y0; y <= y1; ++y) cells_[Key(x, y)].push_back({l, k});
        }
      }
    }
  }

  // Segments in the 3 x 3 cells around p (every segment within one cell width of p).
  template <typename Visit>
  void Near(const Eigen::Vector2d& p, Visit visit) const {
    const auto [cx, cy] = Cell(p);
    for (std::int64_t x = cx - 1; x <= cx + 1; ++x) {
      for (std::int64_t y = cy - 1; y <= cy + 1; ++y) {
        const auto it = cells_.find(Key(x, y));
        if (it == cells_.end()) continue;
        for (const Segment& s : it->second) visit(s);
      }
    }
  }

 private:
  static std::pair<std::int64_t, std::int64_t> Cell(const Eigen::Vector2d& p) {
    return {GridCell(p.x(), kMaxLaneWidthM), GridCell(p.y(), kMaxLaneWidthM)};
  }
  static std::int64_t Key(std::int64_t x, std::int64_t y) {
    return x * 73856093LL ^ y * 19349663LL;
  }
  std::unordered_map<std::int64_t, std::vector<Segment>> cells_;
};

// A line's left neighbour at one sample: which line, and where along it (arc length).
struct Neighbour {
  std::size_t line = std::numeric_limits<std::size_t>::max();
  double arc = 0.0;
  bool found() const { return line != std::numeric_limits<std::size_t>::max(); }
};

// A lane: line `right` from arc s_a to s_b, its left neighbour `left` at the run's samples.
struct Run {
  std::size_t right = 0, left = 0;
  std::vector<double> s, t;  // corresponding arc lengths on right and left, ascending
};

// Linear interpolation of y(x) over ascending xs (clamped).
double Interpolate(const std::vector<double>& xs, const std::vector<double>& ys, double x) {
  if (x <= xs.front()) return ys.front();
  if (x >= xs.back()) return ys.back();
  const std::size_t k = static_cast<std::size_t>(std::upper_bound(xs.begin(), xs.end(), x) -
                                                 xs.begin());  // xs[k - 1] <= x < xs[k]
  const double f = (x - xs[k - 1]) / std::max(xs[k] - xs[k - 1], 1e-12);
  return ys[k - 1] + f * (ys[k] - ys[k - 1]);
}

// Adds a cut at s to a line of length `length` unless it is within kEndSnapM of an end or
// kMergeCutsM of a cut it has; returns whether it was added.
bool AddCut(double s, double length, std::vector<double>* cuts) {
  if (s < kEndSnapM || s > length - kEndSnapM) return false;
  for (double c : *cuts) {
    if (std::abs(c - s) < kMergeCutsM) return false;
  }
  cuts->push_back(s);
  return true;
}

// The piece of a line (between its ascending cuts) that arc length s lies in.
std::size_t PieceAt(const std::vector<double>& cuts, double s) {
  return static_cast<std::size_t>(std::upper_bound(cuts.begin(), cuts.end(), s) - cuts.begin());
}

std::vector<Neighbour> LeftNeighbours(const std::vector<std::vector<Eigen::Vector3d>>& lines,
                                      const std::vector<std::vector<double>>& arcs,
                                      const SegmentGrid& grid, std::size_t i) {
  const std::vector<Eigen::Vector3d>& line = lines[i];
  std::vector<Neighbour> result(line.size());
  const double min_cos = std::cos(kMaxNeighbourAngleRad);
  for (std::size_t k = 0; k < line.size(); ++k) {
    const Eigen::Vector2d p = line[k].head<2>();
    const Eigen::Vector2d d = DirectionAt(line, k);
    if (d.isZero()) continue;
    // Per other line, its nearest point to p (few lines are near: a linear list).
    struct Nearest {
      std::size_t line;
      double dist, arc;
      Eigen::Vector2d offset, direction;
    };
    std::vector<Nearest> nearest;
    grid.Near(p, [&](const SegmentGrid::Segment& s) {
      if (s.line == i) return;
      const Eigen::Vector2d a = lines[s.line][s.index].head<2>();
      const Eigen::Vector2d b = lines[s.line][s.index + 1].head<2>();
      const Eigen::Vector2d ab = b - a;
      const double len2 = ab.squaredNorm();
      if (len2 < 1e-12) return;
      const double u = std::clamp((p - a).dot(ab) / len2, 0.0, 1.0);
      const Eigen::Vector2d q = a + u * ab;
      const Nearest candidate{s.line, (q - p).norm(), arcs[s.line][s.index] + u * std::sqrt(len2),
                              q - p, ab / std::sqrt(len2)};
      auto it = std::find_if(nearest.begin(), nearest.end(),
                             [&](const Nearest& n) { return n.line == s.line; });
      if (it == nearest.end()) {
        nearest.push_back(candidate);
      } else if (candidate.dist < it->dist) {
        *it = candidate;
      }
    });
    double best = std::numeric_limits<double>::infinity();
    for (const Nearest& n : nearest) {
      if (n.dist > kMaxLaneWidthM) continue;  // a cell shared by the hash, not a neighbour
      const Eigen::Vector2d& v = n.offset;
      const Eigen::Vector2d& dj = n.direction;
      if (d.dot(dj) < min_cos) continue;              // not parallel, or the other way
      if (std::abs(v.dot(dj)) > kPastEndM) continue;  // p lies beyond the line's end
      const double left = Cross(d, v);                // > 0: to the left of the line
      if (left <= kSameLineM || left > kMaxLaneWidthM) continue;
      if (left < best) {
        best = left;
        result[k].line = n.line;
        result[k].arc = n.arc;
      }
    }
    // The nearest line to the left closer than a lane: this line and that one are one
    // boundary (a double line); the lane to the left starts at that one.
    if (best < kMinLaneWidthM) result[k] = Neighbour();
  }
  return result;
}

}  // namespace

std::pair<double, double> PieceRange(const LaneletLayout& layout, std::size_t line,
                                     std::size_t piece, double length_m) {
  const std::vector<double>& cuts = layout.cuts[line];
  return {piece == 0 ? 0.0 : cuts[piece - 1], piece < cuts.size() ? cuts[piece] : length_m};
}

std::vector<double> ArcLengths(const std::vector<Eigen::Vector3d>& polyline) {
  std::vector<double> arc(polyline.size(), 0.0);
  for (std::size_t k = 1; k < polyline.size(); ++k) {
    arc[k] = arc[k - 1] + (polyline[k] - polyline[k - 1]).head<2>().norm();
  }
  return arc;
}

Eigen::Vector3d PointAtArcLength(const std::vector<Eigen::Vector3d>& polyline,
                                 const std::vector<double>& arc, double s) {
  if (s <= arc.front()) return polyline.front();
  if (s >= arc.back()) return polyline.back();
  const std::size_t k =
      static_cast<std::size_t>(std::upper_bound(arc.begin(), arc.end(), s) - arc.begin());
  const double f = (s - arc[k - 1]) / std::max(arc[k] - arc[k - 1], 1e-12);
  return polyline[k - 1] + f * (polyline[k] - polyline[k - 1]);
}

std::vector<Eigen::Vector3d> LaneOrientedAlongDrive(std::vector<Eigen::Vector3d> polyline,
                                                    const std::vector<StampedPose>& trajectory,
                                                    bool* reversed) {
  if (reversed) *reversed = false;
  if (polyline.size() < 2 || trajectory.empty()) return polyline;
  const std::size_t middle = polyline.size() / 2;
  const Eigen::Vector2d p = polyline[middle].head<2>();
  const StampedPose* nearest = &trajectory.front();
  double best = std::numeric_limits<double>::infinity();
  for (const StampedPose& pose : trajectory) {
    const double d2 = (pose.T_map_base.translation().head<2>() - p).squaredNorm();
    if (d2 < best) {
      best = d2;
      nearest = &pose;
    }
  }
  const Eigen::Vector2d heading = nearest->T_map_base.linear().col(0).head<2>();
  if (DirectionAt(polyline, middle).dot(heading) < 0.0) {
    std::reverse(polyline.begin(), polyline.end());
    if (reversed) *reversed = true;
  }
  return polyline;
}

LaneletLayout PairLanelets(const std::vector<std::vector<Eigen::Vector3d>>& lines) {
  LaneletLayout layout;
  layout.cuts.resize(lines.size());
  std::vector<std::vector<double>> arcs;
  for (const auto& line : lines) arcs.push_back(ArcLengths(line));
  const SegmentGrid grid(lines);

  // Runs of one left neighbour, at least kMinLaneletLengthM long on both bounds.
  std::vector<Run> runs;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    if (lines[i].size() < 2) continue;
    const std::vector<Neighbour> left = LeftNeighbours(lines, arcs, grid, i);
    std::size_t k = 0;
    while (k < left.size()) {
      if (!left[k].found()) {
        ++k;
        continue;
      }
      Run run{i, left[k].line, {arcs[i][k]}, {left[k].arc}};
      std::size_t e = k + 1;
      while (e < left.size() && left[e].line == run.left && left[e].arc >= run.t.back()) {
        run.s.push_back(arcs[i][e]);
        run.t.push_back(left[e].arc);
        ++e;
      }
      if (run.s.back() - run.s.front() >= kMinLaneletLengthM &&
          run.t.back() - run.t.front() >= 0.5 * kMinLaneletLengthM) {
        runs.push_back(std::move(run));
      }
      k = e;
    }
  }

  // Cuts: every run's ends on both of its bounds, then cuts inside runs carried across.
  auto length = [&](std::size_t line) { return arcs[line].back(); };
  for (const Run& r : runs) {
    AddCut(r.s.front(), length(r.right), &layout.cuts[r.right]);
    AddCut(r.s.back(), length(r.right), &layout.cuts[r.right]);
    AddCut(r.t.front(), length(r.left), &layout.cuts[r.left]);
    AddCut(r.t.back(), length(r.left), &layout.cuts[r.left]);
  }
  for (int pass = 0; pass < kMaxCutPasses; ++pass) {
    bool added = false;
    for (const Run& r : runs) {
      const std::vector<double> right_cuts = layout.cuts[r.right];
      for (double c : right_cuts) {
        if (c <= r.s.front() + kMergeCutsM || c >= r.s.back() - kMergeCutsM) continue;
        added |= AddCut(Interpolate(r.s, r.t, c), length(r.left), &layout.cuts[r.left]);
      }
      const std::vector<double> left_cuts = layout.cuts[r.left];
      for (double c : left_cuts) {
        if (c <= r.t.front() + kMergeCutsM || c >= r.t.back() - kMergeCutsM) continue;
        added |= AddCut(Interpolate(r.t, r.s, c), length(r.right), &layout.cuts[r.right]);
      }
    }
    if (!added) break;
  }
  for (auto& cuts : layout.cuts) std::sort(cuts.begin(), cuts.end());

  // Each run's pieces, one lanelet per corresponding pair.
  for (const Run& r : runs) {
    const std::vector<double>& rc = layout.cuts[r.right];
    const std::vector<double>& lc = layout.cuts[r.left];
    const std::size_t r0 = PieceAt(rc, r.s.front() + kMergeCutsM);
    const std::size_t r1 = PieceAt(rc, r.s.back() - kMergeCutsM);
    const std::size_t l0 = PieceAt(lc, r.t.front() + kMergeCutsM);
    const std::size_t l1 = PieceAt(lc, r.t.back() - kMergeCutsM);
    if (r1 < r0 || l1 < l0 || r1 - r0 != l1 - l0) {
      ++layout.runs_left_out;
      continue;
    }
    for (std::size_t n = 0; n <= r1 - r0; ++n) {
      layout.lanelets.push_back({r.right, r0 + n, r.left, l0 + n});
    }
  }
  return layout;
}

}  // namespace ipm_road_mapper
