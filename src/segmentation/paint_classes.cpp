#include "ipm_road_mapper/segmentation/paint_classes.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

namespace ipm_road_mapper {
namespace segmentation {
namespace {

constexpr double kDegToRad = M_PI / 180.0;

// Angle (rad, [0, pi/2]) between a piece's direction and the travel (base_link x).
double TurnFromTravel(const Eigen::Vector2d& direction) {
  return std::acos(std::min(1.0, std::abs(direction.x())));
}

double MeanProbability(const std::vector<PaintPiece>& pieces, const std::vector<int>& members) {
  double sum = 0.0, weight = 0.0;
  for (const int i : members) {
    sum += pieces[i].paint_probability * pieces[i].area_m2;
    weight += pieces[i].area_m2;
  }
  return weight > 0.0 ? sum / weight : 0.0;
}

// Pushes the instance, or counts it when its confidence is under the bound.
void Emit(PaintInstance instance, const ClassifyOptions& options, ClassifyCounters* counters,
          std::vector<PaintInstance>* out) {
  if (instance.confidence < options.min_confidence) {
    ++counters->low_confidence;
    return;
  }
  out->push_back(std::move(instance));
}

// True when the stripes of a stack are laid as a crossing's: along the travel, side by side
// square to their direction (the line through their centers within crossing_max_turn_deg of
// square), a stripe's width or two apart. Hatching is laid along a slanted border, and wider
// apart.
bool LaidAsCrossing(const std::vector<PaintPiece>& pieces, const std::vector<int>& stack,
                    const ClassifyOptions& options) {
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const int i : stack) mean += pieces[i].center;
  mean /= static_cast<double>(stack.size());
  Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
  for (const int i : stack) {
    scatter += (pieces[i].center - mean) * (pieces[i].center - mean).transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(scatter);
  const Eigen::Vector2d axis = eigen.eigenvectors().col(1);
  const Eigen::Vector2d stripe = pieces[stack.front()].direction;
  const double square = std::abs(axis.dot(stripe));  // cos of the angle: 0 when square
  // The centers' extent along the axis (uniformly spaced: sqrt(12 variance)).
  const double spread =
      std::sqrt(std::max(0.0, eigen.eigenvalues()(1)) * 12.0 / static_cast<double>(stack.size()));
  const double spacing = spread / static_cast<double>(stack.size() - 1);
  // A crossing on the road driven runs along the travel; hatching seen obliquely can look
  // square and close in one view, never along the travel as well.
  return square < std::sin(options.crossing_max_turn_deg * kDegToRad) &&
         spacing <= options.crossing_max_spacing_m &&
         TurnFromTravel(stripe) < options.crossing_max_turn_deg * kDegToRad;
}

// A stack of parallel strokes: crossing stripes when laid as a crossing, else one hatched
// area (chevrons, diagonal hatching).
void ClassifyStack(const std::vector<PaintPiece>& pieces, const std::vector<int>& stack,
                   const ClassifyOptions& options, ClassifyCounters* counters,
                   std::vector<PaintInstance>* out) {
  const double probability = MeanProbability(pieces, stack);
  const double count_score = std::min(1.0, 0.25 * static_cast<double>(stack.size() + 1));
  if (LaidAsCrossing(pieces, stack, options)) {
    for (const int i : stack) {
      Emit({PaintClass::kCrossingStripe, {i}, probability * count_score}, options, counters, out);
    }
    return;
  }
  Emit({PaintClass::kHatchedArea, stack, probability * count_score}, options, counters, out);
}

// A chain's span along its line, its pieces' length, and its largest gap.
struct ChainShape {
  double span_m = 0.0, painted_m = 0.0, max_gap_m = 0.0, max_piece_m = 0.0, width_m = 0.0;
};

ChainShape MeasureChain(const std::vector<PaintPiece>& pieces, const std::vector<int>& chain) {
  ChainShape shape;
  const Eigen::Vector2d u =
      (pieces[chain.back()].center - pieces[chain.front()].center).normalized();
  const Eigen::Vector2d along = chain.size() > 1 ? u : pieces[chain.front()].direction;
  double lo = 1e18, hi = -1e18, area = 0.0;
  for (std::size_t k = 0; k < chain.size(); ++k) {
    const PaintPiece& p = pieces[chain[k]];
    for (const Eigen::Vector2d& end : {p.Start(), p.End()}) {
      lo = std::min(lo, end.dot(along));
      hi = std::max(hi, end.dot(along));
    }
    shape.painted_m += p.length_m;
    shape.max_piece_m = std::max(shape.max_piece_m, p.length_m);
    area += p.area_m2;
    if (k == 0) continue;
    const PaintPiece& q = pieces[chain[k - 1]];
    const double gap = std::abs((p.center - q.center).dot(along)) - 0.5 * (p.length_m + q.length_m);
    shape.max_gap_m = std::max(shape.max_gap_m, gap);
  }
  shape.span_m = hi - lo;
  shape.width_m = area / std::max(shape.painted_m, 1e-9);
  return shape;
}

// A chain of strokes: a lane line (dashed when its gaps and dashes say so), a stop line (one
// wide stroke across the travel), or nothing.
void ClassifyChain(const std::vector<PaintPiece>& pieces, const std::vector<int>& chain,
                   const ClassifyOptions& options, const GroundFootprint& footprint,
                   ClassifyCounters* counters, std::vector<PaintInstance>* out) {
  const ChainShape shape = MeasureChain(pieces, chain);
  // The nearest piece's footprint: the line is at its sharpest there.
  double blur_m = 1e18;
  for (const int i : chain) {
    blur_m = std::min(blur_m, options.line_blur_px *
                                  footprint.AcrossStroke(pieces[i].center, pieces[i].direction));
  }
  const double probability = MeanProbability(pieces, chain);
  const PaintPiece& first = pieces[chain.front()];
  if (chain.size() == 1 &&
      TurnFromTravel(first.direction) > options.stop_line_min_turn_deg * kDegToRad &&
      first.length_m >= options.stop_line_min_length_m &&
      first.width_m <= options.stop_line_max_width_m &&
      first.width_m > 0.5 * options.max_line_width_m) {
    Emit({PaintClass::kStopLine, chain, 0.6 * probability}, options, counters, out);
    return;
  }
  if (shape.width_m > options.max_line_width_m + blur_m) {
    ++counters->wide_strokes;
    return;
  }
  if (shape.span_m < options.min_line_span_m) {
    ++counters->short_lines;
    return;
  }
  // The dash pattern: gaps of a dash length or more between pieces no longer than a dash.
  PaintClass line_class = PaintClass::kLaneSolid;
  double clarity = 1.0;
  if (chain.size() >= 2) {
    const bool dashed =
        shape.max_gap_m >= options.min_dash_gap_m && shape.max_piece_m <= options.max_dash_length_m;
    line_class = dashed ? PaintClass::kLaneDashed : PaintClass::kLaneSolid;
  } else if (first.length_m < options.max_dash_length_m) {
    // One piece shorter than a dash: a whole dash when both its ends are seen.
    line_class = PaintClass::kLaneDashed;
    clarity = first.touches_edge ? 0.5 : 0.75;
  }
  const double length_score = std::min(1.0, 0.4 + shape.span_m / 10.0);
  Emit({line_class, chain, probability * clarity * length_score}, options, counters, out);
}

// A blob: an arrow when its size and direction fit one, else nothing (a curb, a shadow).
void ClassifyBlob(const std::vector<PaintPiece>& pieces, int i, const ClassifyOptions& options,
                  ClassifyCounters* counters, std::vector<PaintInstance>* out) {
  const PaintPiece& p = pieces[i];
  const double extent_width = p.length_m > 0.0 ? p.area_m2 / p.length_m : 0.0;
  const bool arrow = TurnFromTravel(p.direction) < options.arrow_max_turn_deg * kDegToRad &&
                     p.length_m >= options.arrow_min_length_m &&
                     p.length_m <= options.arrow_max_length_m &&
                     extent_width <= options.arrow_max_width_m && !p.touches_edge;
  if (!arrow) {
    ++counters->blobs;
    return;
  }
  Emit({PaintClass::kArrow, {i}, 0.5 * p.paint_probability}, options, counters, out);
}

// Pieces inside a stack's stripes (their bounding box on the stripes' axes, grown by
// area_margin_m) join the stack's instances emitted from `first` on (a hatched area, or the
// nearest crossing stripe): a stripe broken or merged at its ends, the blob where two chevron
// arms meet. No stray piece of hatching or of a crossing becomes a line.
void AbsorbIntoStack(const std::vector<PaintPiece>& pieces, const std::vector<int>& stack,
                     const ClassifyOptions& options, std::size_t first,
                     std::vector<PaintInstance>* instances, std::vector<bool>* used) {
  if (first >= instances->size()) return;  // nothing emitted (low confidence)
  const Eigen::Vector2d u = pieces[stack.front()].direction;
  const Eigen::Vector2d v(-u.y(), u.x());
  double lo_u = 1e18, hi_u = -1e18, lo_v = 1e18, hi_v = -1e18;
  for (const int i : stack) {
    for (const Eigen::Vector2d& end : {pieces[i].Start(), pieces[i].End()}) {
      lo_u = std::min(lo_u, end.dot(u));
      hi_u = std::max(hi_u, end.dot(u));
      lo_v = std::min(lo_v, end.dot(v));
      hi_v = std::max(hi_v, end.dot(v));
    }
  }
  const double m = options.area_margin_m;
  for (std::size_t i = 0; i < pieces.size(); ++i) {
    const double a = pieces[i].center.dot(u), b = pieces[i].center.dot(v);
    if ((*used)[i] || a < lo_u - m || a > hi_u + m || b < lo_v - m || b > hi_v + m) continue;
    if (pieces[i].length_m > options.max_dash_length_m) continue;  // a line passing by
    std::size_t nearest = first;
    double best = 1e18;
    for (std::size_t k = first; k < instances->size(); ++k) {
      for (const int j : (*instances)[k].pieces) {
        const double d = (pieces[j].center - pieces[i].center).squaredNorm();
        if (d < best) {
          best = d;
          nearest = k;
        }
      }
    }
    (*instances)[nearest].pieces.push_back(static_cast<int>(i));
    (*used)[i] = true;
  }
}

}  // namespace

double GroundFootprint::AcrossStroke(const Eigen::Vector2d& xy,
                                     const Eigen::Vector2d& direction) const {
  const double range = std::max(1.0, xy.x());
  const double across_view = range / focal_px;
  const double along_view = range * range / (focal_px * height_m);
  // The stroke's normal (-d.y, d.x): its x part meets the along-view footprint.
  return std::abs(direction.y()) * along_view + std::abs(direction.x()) * across_view;
}

const char* ToString(PaintClass paint_class) {
  switch (paint_class) {
    case PaintClass::kLaneSolid:
      return "lane_solid";
    case PaintClass::kLaneDashed:
      return "lane_dashed";
    case PaintClass::kCrossingStripe:
      return "crossing_stripe";
    case PaintClass::kStopLine:
      return "stop_line";
    case PaintClass::kArrow:
      return "arrow";
    case PaintClass::kHatchedArea:
      return "hatched_area";
  }
  return "unknown";
}

std::vector<PaintInstance> ClassifyPaint(const std::vector<PaintPiece>& pieces,
                                         const GroupOptions& group_options,
                                         const ClassifyOptions& options,
                                         const GroundFootprint& footprint,
                                         ClassifyCounters* counters) {
  std::vector<PaintInstance> instances;
  std::vector<bool> used(pieces.size(), false);
  const std::vector<std::vector<int>> stacks = StackStrokes(pieces, group_options);
  for (const std::vector<int>& stack : stacks) {
    for (const int i : stack) used[i] = true;
  }
  for (const std::vector<int>& stack : stacks) {
    const std::size_t first = instances.size();
    ClassifyStack(pieces, stack, options, counters, &instances);
    AbsorbIntoStack(pieces, stack, options, first, &instances, &used);
  }
  for (const std::vector<int>& chain : ChainStrokes(pieces, used, group_options)) {
    ClassifyChain(pieces, chain, options, footprint, counters, &instances);
    for (const int i : chain) used[i] = true;
  }
  for (std::size_t i = 0; i < pieces.size(); ++i) {
    if (!used[i]) ClassifyBlob(pieces, static_cast<int>(i), options, counters, &instances);
  }
  return instances;
}

}  // namespace segmentation
}  // namespace ipm_road_mapper
