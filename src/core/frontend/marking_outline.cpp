#include "marking_outline.h"

#include <algorithm>
#include <cmath>

namespace ipm_road_mapper {
namespace extraction {
namespace {

// Outline edges are sampled this densely (px) to find where the IPM stops mapping and
// whether another instance lies just outside them.
constexpr double kSampleStepPx = 4.0;
// An occluder pixel is looked for this far (px) outside an edge.
constexpr double kOccluderProbePx = 1.5;
// A vertex is on a rectangle side when within this of its line on the ground (m), plus
// kSideToleranceFraction of its distance from base_link (the footprint of a pixel grows
// with the range).
constexpr double kSideToleranceM = 0.1;
constexpr double kSideToleranceFraction = 0.01;
// A real edge "runs along" a side when its direction is within this angle of the side's.
const double kAlongSideSin = std::sin(10.0 * M_PI / 180.0);

enum Border { kNone = 0, kLeft = 1, kRight = 2, kTop = 4, kBottom = 8 };

int BordersOf(const Eigen::Vector2d& uv, int width, int height, int margin_px) {
  const double near_px = margin_px + 0.5;  // a border pixel's outer edge is at -0.5
  int borders = kNone;
  if (uv.x() <= near_px) borders |= kLeft;
  if (uv.x() >= width - 1 - near_px) borders |= kRight;
  if (uv.y() <= near_px) borders |= kTop;
  if (uv.y() >= height - 1 - near_px) borders |= kBottom;
  return borders;
}

// +1 when the outline is counter-clockwise in (u, v) with v down (positive shoelace area).
double Orientation(const std::vector<Eigen::Vector2d>& outline) {
  double twice_area = 0.0;
  for (std::size_t i = 0; i < outline.size(); ++i) {
    const Eigen::Vector2d& a = outline[i];
    const Eigen::Vector2d& b = outline[(i + 1) % outline.size()];
    twice_area += a.x() * b.y() - b.x() * a.y();
  }
  return twice_area >= 0.0 ? 1.0 : -1.0;
}

// True when most probes just outside the edge a -> b hit pixels of another instance that
// is no lane (a lane line is paint on the road beside or across a marking, it hides none).
bool OccludedEdge(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double orientation,
                  const cv::Mat& mask, int value, const ClassTable& classes) {
  const Eigen::Vector2d d = b - a;
  const double length = d.norm();
  if (length < 1e-9) return false;
  // Outward normal: right of the direction for a positive-area outline (v down).
  const Eigen::Vector2d outward = orientation * Eigen::Vector2d(d.y(), -d.x()) / length;
  const int samples = std::clamp(static_cast<int>(length / kSampleStepPx), 1, 64);
  int hits = 0, probes = 0;
  for (int k = 0; k < samples; ++k) {
    const Eigen::Vector2d p = a + d * ((k + 0.5) / samples) + kOccluderProbePx * outward;
    const int col = static_cast<int>(std::lround(p.x()));
    const int row = static_cast<int>(std::lround(p.y()));
    if (col < 0 || row < 0 || col >= mask.cols || row >= mask.rows) continue;
    ++probes;
    const int other = mask.at<std::uint16_t>(row, col);
    if (other < kInstanceIdFactor || other == value) continue;
    const ClassInfo* info = classes.Find(ClassIdOf(other));
    if (info == nullptr || info->kind != ElementKind::kLane) ++hits;
  }
  return probes > 0 && 2 * hits > probes;
}

}  // namespace

std::vector<std::uint8_t> CutEdges(std::vector<Eigen::Vector2d>* outline_uv, const cv::Mat& mask,
                                   int value, const ClassTable& classes, int margin_px) {
  std::vector<Eigen::Vector2d>& outline = *outline_uv;
  auto borders = [&](const Eigen::Vector2d& uv) {
    return BordersOf(uv, mask.cols, mask.rows, margin_px);
  };
  // A vertex on the border between two edges that are not along it (a marking whose corner
  // just leaves the image) is where the view cuts the marking too: it becomes a zero-length
  // cut edge, so that its sides are labeled like those of any other cut.
  std::vector<Eigen::Vector2d> split;
  const std::size_t n0 = outline.size();
  for (std::size_t i = 0; i < n0; ++i) {
    split.push_back(outline[i]);
    const int here = borders(outline[i]);
    if (n0 >= 3 && here != kNone && (here & borders(outline[(i + n0 - 1) % n0])) == kNone &&
        (here & borders(outline[(i + 1) % n0])) == kNone) {
      split.push_back(outline[i]);
    }
  }
  outline.swap(split);
  const std::size_t n = outline.size();
  std::vector<std::uint8_t> cut(n, 0);
  if (n < 2) return cut;
  const double orientation = Orientation(outline);
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d& a = outline[i];
    const Eigen::Vector2d& b = outline[(i + 1) % n];
    cut[i] =
        (borders(a) & borders(b)) != kNone || OccludedEdge(a, b, orientation, mask, value, classes);
  }
  return cut;
}

bool ClipOutlineToGround(const Ipm& ipm, const std::vector<Eigen::Vector2d>& outline_uv,
                         const std::vector<std::uint8_t>& edge_cut,
                         std::vector<Eigen::Vector2d>* kept_uv,
                         std::vector<Eigen::Vector2d>* kept_base,
                         std::vector<std::uint8_t>* kept_cut) {
  kept_uv->clear();
  kept_base->clear();
  kept_cut->clear();
  const std::size_t n = outline_uv.size();
  // Every sample of every edge (t = 0 is the edge's first vertex), with its ground point.
  struct Sample {
    Eigen::Vector2d uv;
    Eigen::Vector2d base;
    std::size_t edge;
    bool vertex;
    bool maps;
  };
  std::vector<Sample> samples;
  bool all_map = true;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d& a = outline_uv[i];
    const Eigen::Vector2d d = outline_uv[(i + 1) % n] - a;
    const int steps = std::clamp(static_cast<int>(std::ceil(d.norm() / kSampleStepPx)), 1, 1000);
    for (int k = 0; k < steps; ++k) {
      Sample s{a + d * (static_cast<double>(k) / steps), Eigen::Vector2d::Zero(), i, k == 0, false};
      Eigen::Vector3d p_base;
      s.maps = ipm.PixelToGround(s.uv, &p_base) == IpmStatus::kOk;
      if (s.maps) s.base = p_base.head<2>();
      all_map = all_map && s.maps;
      samples.push_back(s);
    }
  }
  if (all_map) {  // nothing to clip: the outline's own vertices
    for (std::size_t i = 0; i < samples.size(); ++i) {
      if (!samples[i].vertex) continue;
      kept_uv->push_back(samples[i].uv);
      kept_base->push_back(samples[i].base);
      kept_cut->push_back(edge_cut[samples[i].edge]);
    }
    return n >= 1;
  }
  // Keep the vertices that map and the last / first sample that maps around each gap; the
  // edge to the next kept point is the outline's edge when no sample between fails, else the
  // clip chord (cut).
  const std::size_t m = samples.size();
  std::vector<std::size_t> kept;
  for (std::size_t k = 0; k < m; ++k) {
    if (!samples[k].maps) continue;
    const bool before_gap = !samples[(k + 1) % m].maps;
    const bool after_gap = !samples[(k + m - 1) % m].maps;
    if (samples[k].vertex || before_gap || after_gap) kept.push_back(k);
  }
  if (kept.size() < 3) return false;
  for (std::size_t j = 0; j < kept.size(); ++j) {
    const Sample& s = samples[kept[j]];
    kept_uv->push_back(s.uv);
    kept_base->push_back(s.base);
    kept_cut->push_back(!samples[(kept[j] + 1) % m].maps ? 1 : edge_cut[s.edge]);
  }
  return true;
}

void LabelSides(MarkingObservation* marking) {
  const std::vector<Eigen::Vector2d>& base = marking->outline_base;
  const std::vector<Eigen::Vector2d>& uv = marking->outline_uv;
  const std::vector<std::uint8_t>& cut = marking->outline_edge_cut;
  const std::size_t n = base.size();
  for (int s = 0; s < 4; ++s) {
    marking->side_uv[s].clear();
    marking->side_measured[s] = true;
  }
  if (n == 0 || cut.size() != n || uv.size() != n) return;  // no labels: a whole view
  for (int s = 0; s < 4; ++s) {
    const Eigen::Vector2d c0 = marking->corners_base[s].head<2>();
    const Eigen::Vector2d c1 = marking->corners_base[(s + 1) % 4].head<2>();
    const Eigen::Vector2d along = (c1 - c0).normalized();
    const Eigen::Vector2d outward(along.y(), -along.x());  // corners are counter-clockwise
    const double extreme = outward.dot(c0);
    bool measured = true;
    std::vector<std::pair<double, Eigen::Vector2d>> on_side;  // (position along, pixel)
    for (std::size_t i = 0; i < n && measured; ++i) {
      const double tolerance = kSideToleranceM + kSideToleranceFraction * base[i].norm();
      if (outward.dot(base[i]) < extreme - tolerance) continue;
      const std::size_t previous = (i + n - 1) % n;
      const bool cut_before = cut[previous] != 0, cut_after = cut[i] != 0;
      if (cut_before && cut_after) measured = false;
      if (cut_before != cut_after) {
        // The real edge at this vertex must run along the side to continue past the cut.
        const std::size_t other = cut_before ? (i + 1) % n : previous;
        const Eigen::Vector2d edge = base[other] - base[i];
        if (edge.norm() < 1e-9 || std::abs(outward.dot(edge.normalized())) > kAlongSideSin) {
          measured = false;
        }
      }
      on_side.emplace_back(along.dot(base[i]), uv[i]);
    }
    marking->side_measured[s] = measured;
    if (!measured || on_side.empty()) continue;
    // The ends of the observed boundary on the side, and its middle point.
    std::sort(on_side.begin(), on_side.end(),
              [](const auto& a, const auto& b) { return a.first < b.first; });
    marking->side_uv[s].push_back(on_side.front().second);
    if (on_side.size() > 2) marking->side_uv[s].push_back(on_side[on_side.size() / 2].second);
    if (on_side.size() > 1) marking->side_uv[s].push_back(on_side.back().second);
  }
}

}  // namespace extraction
}  // namespace ipm_road_mapper
