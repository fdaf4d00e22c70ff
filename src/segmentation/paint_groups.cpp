#include "ipm_road_mapper/segmentation/paint_groups.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

namespace ipm_road_mapper {
namespace segmentation {
namespace {

constexpr double kDegToRad = M_PI / 180.0;

double Cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

// A possible link between an end of piece a and an end of piece b, with its cost.
struct Link {
  int a, end_a, b, end_b;
  double cost;
};

// The link between the nearest ends of two strokes when they continue each other: directions
// within chain_max_turn, the gap end to end (not side by side) and the chord between the ends
// along the mean direction (on a circular arc the chord is parallel to the mean tangent).
bool ContinueEachOther(const PaintPiece& a, const PaintPiece& b, const GroupOptions& options,
                       Link* link) {
  const Eigen::Vector2d db = Aligned(b.direction, a.direction);
  if (a.direction.dot(db) < std::cos(options.chain_max_turn_deg * kDegToRad)) return false;
  const Eigen::Vector2d mean_direction = (a.direction + db).normalized();
  const Eigen::Vector2d ends_a[2] = {a.Start(), a.End()};
  const Eigen::Vector2d ends_b[2] = {b.Start(), b.End()};
  double best = 1e18;
  for (int i = 0; i < 2; ++i) {
    for (int j = 0; j < 2; ++j) {
      const double d = (ends_b[j] - ends_a[i]).norm();
      if (d < best) {
        best = d;
        *link = {0, i, 0, j, d};
      }
    }
  }
  if (best > options.chain_max_gap_m) return false;
  // End to end: b's center lies beyond a's end along the line, and a's beyond b's.
  const double along = (b.center - a.center).dot(mean_direction);
  if (std::abs(along) < 0.5 * (a.length_m + b.length_m) - options.chain_max_offset_m) {
    return false;
  }
  const Eigen::Vector2d chord = ends_b[link->end_b] - ends_a[link->end_a];
  const double lateral = std::abs(Cross(mean_direction, chord));
  if (lateral > options.chain_max_offset_m + 0.05 * chord.norm()) return false;
  link->cost = chord.norm() + 10.0 * lateral;
  return true;
}

}  // namespace

Eigen::Vector2d Aligned(const Eigen::Vector2d& direction, const Eigen::Vector2d& reference) {
  return direction.dot(reference) < 0.0 ? Eigen::Vector2d(-direction) : direction;
}

bool IsStroke(const PaintPiece& piece, const GroupOptions& options) {
  return piece.width_m <= options.max_stroke_width_m &&
         piece.length_m >= options.min_stroke_length_m &&
         piece.length_m >= options.min_stroke_elongation * piece.width_m;
}

std::vector<std::vector<int>> ChainStrokes(const std::vector<PaintPiece>& pieces,
                                           const std::vector<bool>& excluded,
                                           const GroupOptions& options) {
  const int n = static_cast<int>(pieces.size());
  std::vector<bool> stroke(n);
  for (int i = 0; i < n; ++i) stroke[i] = !excluded[i] && IsStroke(pieces[i], options);
  std::vector<Link> links;
  for (int a = 0; a < n; ++a) {
    for (int b = a + 1; b < n; ++b) {
      Link link{};
      if (!stroke[a] || !stroke[b] || !ContinueEachOther(pieces[a], pieces[b], options, &link)) {
        continue;
      }
      link.a = a;
      link.b = b;
      links.push_back(link);
    }
  }
  std::sort(links.begin(), links.end(),
            [](const Link& x, const Link& y) { return x.cost < y.cost; });
  // next[i][end]: the piece linked at that end (-1: none). Cheapest links first, one per end,
  // never closing a loop.
  std::vector<std::array<int, 2>> next(n, {-1, -1});
  std::vector<int> chain_of(n);
  std::iota(chain_of.begin(), chain_of.end(), 0);
  const auto root = [&chain_of](int i) {
    while (chain_of[i] != i) i = chain_of[i] = chain_of[chain_of[i]];
    return i;
  };
  for (const Link& link : links) {
    if (next[link.a][link.end_a] >= 0 || next[link.b][link.end_b] >= 0) continue;
    if (root(link.a) == root(link.b)) continue;
    next[link.a][link.end_a] = link.b;
    next[link.b][link.end_b] = link.a;
    chain_of[root(link.a)] = root(link.b);
  }
  // Walk each chain from one of its ends.
  std::vector<std::vector<int>> chains;
  std::vector<bool> visited(n, false);
  for (int i = 0; i < n; ++i) {
    if (!stroke[i] || visited[i] || (next[i][0] >= 0 && next[i][1] >= 0)) continue;
    std::vector<int> chain;
    int previous = -1, current = i;
    while (current >= 0 && !visited[current]) {
      visited[current] = true;
      chain.push_back(current);
      const int following = next[current][0] != previous ? next[current][0] : next[current][1];
      previous = current;
      current = following;
    }
    chains.push_back(std::move(chain));
  }
  return chains;
}

std::vector<std::vector<int>> StackStrokes(const std::vector<PaintPiece>& pieces,
                                           const GroupOptions& options) {
  const int n = static_cast<int>(pieces.size());
  std::vector<int> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  const auto root = [&parent](int i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  const double min_dot = std::cos(options.stack_max_turn_deg * kDegToRad);
  for (int a = 0; a < n; ++a) {
    if (!IsStroke(pieces[a], options)) continue;
    for (int b = a + 1; b < n; ++b) {
      if (!IsStroke(pieces[b], options)) continue;
      const Eigen::Vector2d db = Aligned(pieces[b].direction, pieces[a].direction);
      if (pieces[a].direction.dot(db) < min_dot) continue;
      const Eigen::Vector2d u = (pieces[a].direction + db).normalized();
      const Eigen::Vector2d offset = pieces[b].center - pieces[a].center;
      const double across = std::abs(Cross(u, offset));
      if (across < options.stack_min_spacing_m || across > options.stack_max_spacing_m) continue;
      const double along = std::abs(offset.dot(u));
      const double overlap = 0.5 * (pieces[a].length_m + pieces[b].length_m) - along;
      if (overlap < options.stack_min_overlap * std::min(pieces[a].length_m, pieces[b].length_m)) {
        continue;
      }
      parent[root(a)] = root(b);
    }
  }
  std::vector<std::vector<int>> groups(n);
  for (int i = 0; i < n; ++i) groups[root(i)].push_back(i);
  std::vector<std::vector<int>> stacks;
  for (std::vector<int>& group : groups) {
    if (group.size() >= 2) stacks.push_back(std::move(group));
  }
  return stacks;
}

}  // namespace segmentation
}  // namespace ipm_road_mapper
