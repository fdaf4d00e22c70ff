// Per-instance geometry of the instance extraction: marking rectangles and lane centerline
// points, computed from an instance's runs (see instance_extraction_runs.h).
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "instance_extraction_runs.h"
#include "marking_outline.h"

namespace ipm_road_mapper {
namespace extraction {
namespace {

// minAreaRect works in float: ground points go in as millimeters (relative to the outline's
// first point) so that float rounding is far below the pixel footprint.
constexpr double kMetersToMm = 1000.0;

// Offsets from a pixel center to the midpoints of its four edges.
constexpr std::array<std::array<double, 2>, 4> kEdgeMidpoints{
    {{-0.5, 0.0}, {0.5, 0.0}, {0.0, -0.5}, {0.0, 0.5}}};

// A directed outline edge as the line n . uv = c (n its outward unit normal).
struct OutlineLine {
  Eigen::Vector2d direction;
  Eigen::Vector2d normal;
  double offset = 0.0;
};

// Union-find root with path halving.
int Root(std::vector<int>* parent, int i) {
  while ((*parent)[i] != i) {
    (*parent)[i] = (*parent)[(*parent)[i]];
    i = (*parent)[i];
  }
  return i;
}

// A piece of an instance smaller than this fraction of its largest piece is segmentation
// debris and is left out of the marking's outline; larger ones (the glyphs of a speed limit,
// the parts of an arrow cut by a gap) belong to the marking.
constexpr double kMinPieceFraction = 0.1;

// Indices of the runs of the instance's significant 8-connected pieces (those with at least
// kMinPieceFraction of the largest piece's pixels), in row-major order. Runs of consecutive
// rows are linked when they overlap or touch diagonally; a two-pointer sweep over each pair
// of rows keeps it linear.
std::vector<int> SignificantPieces(const Run* runs, int run_count) {
  std::vector<int> parent(run_count);
  for (int i = 0; i < run_count; ++i) parent[i] = i;
  int previous_begin = 0, previous_end = 0;  // runs of the row above the current one
  int begin = 0;
  while (begin < run_count) {
    int end = begin;
    while (end < run_count && runs[end].row == runs[begin].row) ++end;
    if (previous_end > previous_begin && runs[previous_begin].row == runs[begin].row - 1) {
      int i = previous_begin, j = begin;
      while (i < previous_end && j < end) {
        if (runs[i].last_col + 1 < runs[j].first_col) {
          ++i;
        } else if (runs[j].last_col + 1 < runs[i].first_col) {
          ++j;
        } else {
          parent[Root(&parent, i)] = Root(&parent, j);
          if (runs[i].last_col < runs[j].last_col) {
            ++i;
          } else {
            ++j;
          }
        }
      }
    }
    previous_begin = begin;
    previous_end = end;
    begin = end;
  }
  std::vector<int> pixels(run_count, 0);
  for (int i = 0; i < run_count; ++i) {
    pixels[Root(&parent, i)] += runs[i].last_col - runs[i].first_col + 1;
  }
  int largest = 0;
  for (int i = 0; i < run_count; ++i) largest = std::max(largest, pixels[Root(&parent, i)]);
  std::vector<int> members;
  for (int i = 0; i < run_count; ++i) {
    if (pixels[Root(&parent, i)] >= kMinPieceFraction * largest) members.push_back(i);
  }
  return members;
}

// Pixel centers of each row's leftmost and rightmost pixel of a piece (the convex hull,
// hence the minimum-area rectangle, depends only on row ends).
std::vector<cv::Point> RowEnds(const Run* runs, const std::vector<int>& members) {
  std::vector<cv::Point> ends;
  std::size_t k = 0;
  while (k < members.size()) {
    const int row = runs[members[k]].row;
    int first_col = runs[members[k]].first_col, last_col = runs[members[k]].last_col;
    for (++k; k < members.size() && runs[members[k]].row == row; ++k) {
      first_col = std::min<int>(first_col, runs[members[k]].first_col);
      last_col = std::max<int>(last_col, runs[members[k]].last_col);
    }
    ends.emplace_back(first_col, row);
    if (last_col != first_col) ends.emplace_back(last_col, row);
  }
  return ends;
}

// Intersection of two lines; false when they are (nearly) parallel.
bool Intersect(const OutlineLine& a, const OutlineLine& b, Eigen::Vector2d* uv) {
  const double det = a.normal.x() * b.normal.y() - a.normal.y() * b.normal.x();
  if (std::abs(det) < 1e-9) return false;
  *uv = Eigen::Vector2d(a.offset * b.normal.y() - b.offset * a.normal.y(),
                        a.normal.x() * b.offset - b.normal.x() * a.offset) /
        det;
  return true;
}

// The midpoints of the pixel edges of the given pixel centers (half a pixel out along rows
// and columns): the outline of pieces too thin for a hull.
std::vector<Eigen::Vector2d> EdgeMidpoints(const std::vector<cv::Point>& centers) {
  std::vector<Eigen::Vector2d> outline;
  for (const cv::Point& center : centers) {
    for (const auto& offset : kEdgeMidpoints) {
      outline.emplace_back(center.x + offset[0], center.y + offset[1]);
    }
  }
  return outline;
}

// The lines of a convex hull's edges (positive area, u right and v down), each moved out by
// half the gap to the next parallel lattice line; collinear edges merged.
std::vector<OutlineLine> OffsetHullLines(const std::vector<cv::Point>& hull) {
  std::vector<OutlineLine> lines;
  for (std::size_t i = 0; i < hull.size(); ++i) {
    const cv::Point step = hull[(i + 1) % hull.size()] - hull[i];
    if (step.x == 0 && step.y == 0) continue;
    const int divisor = std::gcd(std::abs(step.x), std::abs(step.y));
    const Eigen::Vector2d primitive(step.x / divisor, step.y / divisor);
    OutlineLine line;
    line.direction = primitive.normalized();
    line.normal = Eigen::Vector2d(line.direction.y(), -line.direction.x());
    line.offset = line.normal.dot(Eigen::Vector2d(hull[i].x, hull[i].y)) + 0.5 / primitive.norm();
    if (!lines.empty() && std::abs(lines.back().normal.dot(line.direction)) < 1e-12) continue;
    lines.push_back(line);
  }
  while (lines.size() > 1 && std::abs(lines.back().normal.dot(lines.front().direction)) < 1e-12) {
    lines.pop_back();
  }
  return lines;
}

// Sub-pixel outline of a piece from the pixel centers of its row ends. The hull of the
// centers lies inside the true outline: with pixels labeled when their center is inside
// (the 50%-coverage rule), each hull edge runs along a lattice line, and the true edge lies
// between it and the next parallel lattice line, 1/|p| away for the edge's primitive lattice
// vector p. Each hull edge is moved out by half that gap, its expected value: half a pixel
// for row and column edges, 0.35 px for diagonals, almost nothing for long edges of irregular
// slope. Edges that the unequal offsets squeeze out are dropped. Pieces with collinear
// centers (one row, one column) fall back to EdgeMidpoints.
std::vector<Eigen::Vector2d> SubpixelOutline(const std::vector<cv::Point>& centers) {
  std::vector<cv::Point> hull;
  if (centers.size() >= 3) cv::convexHull(centers, hull, /*clockwise=*/false);
  long long twice_area = 0;
  for (std::size_t i = 0; i < hull.size(); ++i) {
    const cv::Point& a = hull[i];
    const cv::Point& b = hull[(i + 1) % hull.size()];
    twice_area += static_cast<long long>(a.x) * b.y - static_cast<long long>(b.x) * a.y;
  }
  if (twice_area == 0) return EdgeMidpoints(centers);
  if (twice_area < 0) std::reverse(hull.begin(), hull.end());  // positive area from here on
  std::vector<OutlineLine> lines = OffsetHullLines(hull);
  std::vector<Eigen::Vector2d> outline;
  while (lines.size() >= 3) {
    const std::size_t n = lines.size();
    outline.assign(n, Eigen::Vector2d::Zero());
    for (std::size_t i = 0; i < n; ++i) {
      if (!Intersect(lines[(i + n - 1) % n], lines[i], &outline[i])) return EdgeMidpoints(hull);
    }
    std::size_t squeezed = n;
    for (std::size_t i = 0; i < n && squeezed == n; ++i) {
      if ((outline[(i + 1) % n] - outline[i]).dot(lines[i].direction) < 0.0) squeezed = i;
    }
    if (squeezed == n) return outline;
    lines.erase(lines.begin() + squeezed);
  }
  return EdgeMidpoints(hull);
}

}  // namespace

std::array<Eigen::Vector2d, 4> BoundingRectangle(const std::vector<Eigen::Vector2d>& outline,
                                                 const Eigen::Vector2d& axis_in) {
  const Eigen::Vector2d axis = axis_in.normalized();
  const Eigen::Vector2d across(-axis.y(), axis.x());
  const Eigen::Vector2d origin = outline.front();
  double a_min = 1e18, a_max = -1e18, c_min = 1e18, c_max = -1e18;
  for (const Eigen::Vector2d& p : outline) {
    const Eigen::Vector2d d = p - origin;
    a_min = std::min(a_min, d.dot(axis));
    a_max = std::max(a_max, d.dot(axis));
    c_min = std::min(c_min, d.dot(across));
    c_max = std::max(c_max, d.dot(across));
  }
  return {origin + a_min * axis + c_min * across, origin + a_max * axis + c_min * across,
          origin + a_max * axis + c_max * across, origin + a_min * axis + c_max * across};
}

void OrderCornersCanonically(std::array<Eigen::Vector3d, 4>* corners_base) {
  std::array<Eigen::Vector3d, 4>& c = *corners_base;
  double twice_area = 0.0;
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector3d& a = c[i];
    const Eigen::Vector3d& b = c[(i + 1) % 4];
    twice_area += a.x() * b.y() - b.x() * a.y();
  }
  if (twice_area < 0.0) std::reverse(c.begin(), c.end());
  int nearest = 0;
  for (int i = 1; i < 4; ++i) {
    if (c[i].head<2>().squaredNorm() < c[nearest].head<2>().squaredNorm()) nearest = i;
  }
  std::rotate(c.begin(), c.begin() + nearest, c.end());
}

GeometryOutcome ExtractMarking(const Run* runs, int run_count, const cv::Mat& mask, int value,
                               const ClassTable& classes, const Ipm& ipm,
                               const IpmErrorModel& error_model, const ExtractionOptions& options,
                               MarkingObservation* marking) {
  std::vector<Eigen::Vector2d> outline_uv =
      SubpixelOutline(RowEnds(runs, SignificantPieces(runs, run_count)));
  const std::vector<std::uint8_t> edge_cut =
      CutEdges(&outline_uv, mask, value, classes, std::max(options.border_margin_px, 0));
  const ClassInfo& class_info = *classes.Find(ClassIdOf(value));
  // Where the outline does not map (cut by the horizon or the IPM range) it is clipped: the
  // part in range is a partial view like one cut by the border.
  if (!ClipOutlineToGround(ipm, outline_uv, edge_cut, &marking->outline_uv, &marking->outline_base,
                           &marking->outline_edge_cut)) {
    return GeometryOutcome::kRange;
  }
  // Along the vehicle's heading until the mapper knows the road's (SetMarkingRectangle).
  const std::array<Eigen::Vector2d, 4> rectangle =
      BoundingRectangle(marking->outline_base, Eigen::Vector2d::UnitX());
  const Eigen::Vector2d center = 0.25 * (rectangle[0] + rectangle[1] + rectangle[2] + rectangle[3]);
  marking->far = center.norm() > options.max_marking_range_m;
  if (marking->far && !(center.norm() <= options.far_marking_range_m)) {
    return GeometryOutcome::kRange;
  }
  if (std::min((rectangle[1] - rectangle[0]).norm(), (rectangle[2] - rectangle[1]).norm()) <
      options.min_rectangle_side_m) {
    return GeometryOutcome::kDegenerate;
  }
  // A cut view is at most as large as the marking: too large already is no marking.
  if (IsOversized(marking->outline_base, class_info)) return GeometryOutcome::kOversized;
  if (!SetMarkingRectangle(ipm, error_model, Eigen::Vector2d::UnitX(), marking)) {
    return GeometryOutcome::kRange;
  }
  // A view that measures at most one side locates the marking in one direction at most
  // (a whole-image blob, one leaving the image on three sides): truncated, no observation.
  const std::array<bool, 4>& sides = marking->side_measured;
  if (sides[0] + sides[1] + sides[2] + sides[3] < 2) return GeometryOutcome::kTruncated;
  // A far view locates a marking meters off along the view: only its whole shape tells which
  // marking it is (a cut one grows no extent; docs/backend.md, "Far views").
  if (marking->far && !marking->Complete()) return GeometryOutcome::kRange;
  return GeometryOutcome::kOk;
}
GeometryOutcome ExtractLane(const Run* runs, int run_count, const ClassInfo& class_info,
                            const Ipm& ipm, const IpmErrorModel& error_model,
                            const ExtractionOptions& options, LaneObservation* lane,
                            std::uint64_t* runs_too_wide, std::uint64_t* rows_doubled) {
  if (run_count <= 0) return GeometryOutcome::kDegenerate;
  const int row_step = std::max(options.lane_row_step, 1);
  const int bottom_row = runs[run_count - 1].row;
  // A run cut by the image's side is not centered on the line: its center is no measurement.
  const int margin = std::max(options.border_margin_px, 0);
  const int last_col = ipm.camera().intrinsics().width - 1 - margin;
  // Runs whose ground width was measured, and those of them too wide for a line.
  int runs_measured = 0, runs_wide = 0;
  // Sampled rows, and those that cross the instance more than once.
  int rows_sampled = 0, rows_several = 0;
  // Rows bottom (near) first; within a row, runs left to right.
  int end = run_count;
  while (end > 0) {
    const int row = runs[end - 1].row;
    int begin = end - 1;
    while (begin > 0 && runs[begin - 1].row == row) --begin;
    if ((bottom_row - row) % row_step == 0) {
      ++rows_sampled;
      if (end - begin > 1) ++rows_several;
      for (int i = begin; i < end; ++i) {
        const Eigen::Vector2d uv(0.5 * (runs[i].first_col + runs[i].last_col), row);
        LanePoint point;
        if (ipm.PixelToGround(uv, &point.p_base) != IpmStatus::kOk) continue;
        point.p_base = ipm.OnGround(point.p_base.head<2>());  // on the ground (drop rounding)
        const std::optional<IpmUncertainty> uncertainty =
            ComputeIpmUncertainty(ipm.camera(), ipm.T_base_cam(), uv, error_model);
        if (!uncertainty) continue;
        // A cut run is at least as wide as its visible part: the width check comes first.
        const std::optional<double> width_m = RunGroundWidth(runs[i], ipm);
        if (width_m) {
          ++runs_measured;
          if (*width_m > class_info.max_width_m + std::sqrt(uncertainty->score)) {
            ++runs_wide;
            continue;
          }
        }
        if (runs[i].first_col < margin || runs[i].last_col > last_col) continue;
        point.uv = uv;
        point.score = uncertainty->score;
        point.cov_base = uncertainty->omega.topLeftCorner<2, 2>();
        lane->points.push_back(point);
      }
    }
    end = begin;
  }
  *runs_too_wide += runs_wide;
  *rows_doubled += static_cast<std::uint64_t>(rows_several);
  if (2 * runs_wide > runs_measured) return GeometryOutcome::kTooWide;
  if (4 * rows_several > rows_sampled) return GeometryOutcome::kDoublesBack;
  return static_cast<int>(lane->points.size()) >= options.min_lane_points
             ? GeometryOutcome::kOk
             : GeometryOutcome::kDegenerate;
}

}  // namespace extraction

bool SetMarkingRectangle(const Ipm& ipm, const IpmErrorModel& error_model,
                         const Eigen::Vector2d& axis_base, MarkingObservation* marking) {
  if (marking->outline_base.empty() || !(axis_base.norm() > 0.0)) return false;
  const std::array<Eigen::Vector2d, 4> rectangle =
      extraction::BoundingRectangle(marking->outline_base, axis_base);
  for (int i = 0; i < 4; ++i) {
    marking->corners_base[i] = ipm.OnGround(rectangle[i]);
  }
  extraction::OrderCornersCanonically(&marking->corners_base);
  extraction::LabelSides(marking);
  for (int i = 0; i < 4; ++i) {
    // A cut corner is no measurement: it may lie behind the camera (a crossing passed over).
    if (!ipm.BaseToPixel(marking->corners_base[i], &marking->corners_uv[i])) {
      if (marking->CornerMeasured(i)) return false;
      marking->corners_uv[i] = Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
    }
  }
  marking->center_base = 0.25 * (marking->corners_base[0] + marking->corners_base[1] +
                                 marking->corners_base[2] + marking->corners_base[3]);
  Eigen::Vector2d center_uv;
  if (!ipm.BaseToPixel(marking->center_base, &center_uv)) return false;
  const std::optional<IpmUncertainty> uncertainty =
      ComputeIpmUncertainty(ipm.camera(), ipm.T_base_cam(), center_uv, error_model);
  if (!uncertainty) return false;
  marking->center_cov_base = uncertainty->omega.topLeftCorner<2, 2>();
  return true;
}
}  // namespace ipm_road_mapper
