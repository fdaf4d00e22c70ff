#include "ipm_road_mapper/core/geometry/catmull_rom_spline.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

namespace ipm_road_mapper {
namespace {

// 5-point Gauss-Legendre rule on [-1, 1]: exact for polynomials up to degree 9. The speed
// |p'(u)| of a cubic is the square root of a quartic; two sub-intervals per integral keep the
// error far below a millimeter even for strongly varying speed.
constexpr double kGaussNodes[5] = {0.0, -0.5384693101056831, 0.5384693101056831,
                                   -0.9061798459386640, 0.9061798459386640};
constexpr double kGaussWeights[5] = {0.5688888888888889, 0.4786286704993665, 0.4786286704993665,
                                     0.2369268850561891, 0.2369268850561891};
constexpr int kQuadratureIntervals = 2;

// Iterations of the safeguarded Newton search of a closest point (it converges in 3-5).
constexpr int kNewtonIterations = 30;

}  // namespace

CatmullRomSpline::CatmullRomSpline(std::vector<Eigen::Vector3d> control_points)
    : control_points_(std::move(control_points)) {
  if (control_points_.size() < 4) {
    throw std::invalid_argument("CatmullRomSpline needs at least 4 control points, got " +
                                std::to_string(control_points_.size()));
  }
  for (const Eigen::Vector3d& c : control_points_) {
    if (!c.allFinite()) throw std::invalid_argument("CatmullRomSpline: non-finite control point");
  }
  cumulative_length_.assign(NumSegments() + 1, 0.0);
  samples_.resize(NumSegments());
  for (int i = 0; i < NumSegments(); ++i) {
    const double length = SegmentArcLength(i, 1.0);
    cumulative_length_[i + 1] = cumulative_length_[i] + length;
    // A grid of step <= ~0.25 m of arc (at least 8 steps) for the coarse closest-point pass.
    SegmentSamples& samples = samples_[i];
    const int steps = std::clamp(static_cast<int>(std::ceil(length / 0.25)), 8, 256);
    samples.step_u = 1.0 / steps;
    samples.points.resize(steps + 1);
    const auto& c = control_points_;
    for (int k = 0; k <= steps; ++k) {
      samples.points[k] = EvaluateSegment<double>(c[i], c[i + 1], c[i + 2], c[i + 3],
                                                  static_cast<double>(k) / steps);
      samples.center += samples.points[k];
      if (k > 0) {
        samples.step_m =
            std::max(samples.step_m, (samples.points[k] - samples.points[k - 1]).norm());
      }
    }
    samples.center /= steps + 1;
    for (const Eigen::Vector3d& p : samples.points) {
      samples.radius = std::max(samples.radius, (p - samples.center).norm());
    }
    // Between two samples the curve strays from them by less than the chord between them.
    samples.radius += samples.step_m;
  }
}

void CatmullRomSpline::Locate(double s, int* segment, double* u) const {
  if (std::isnan(s)) throw std::invalid_argument("CatmullRomSpline: NaN parameter");
  const double s_clamped = std::clamp(s, 0.0, static_cast<double>(NumSegments()));
  *segment = std::min(static_cast<int>(std::floor(s_clamped)), NumSegments() - 1);
  *u = s_clamped - *segment;
}

Eigen::Vector3d CatmullRomSpline::Evaluate(double s) const {
  int i = 0;
  double u = 0.0;
  Locate(s, &i, &u);
  const auto& c = control_points_;
  return EvaluateSegment<double>(c[i], c[i + 1], c[i + 2], c[i + 3], u);
}

Eigen::Vector3d CatmullRomSpline::Derivative(double s) const {
  int i = 0;
  double u = 0.0;
  Locate(s, &i, &u);
  const auto& c = control_points_;
  return SegmentDerivative<double>(c[i], c[i + 1], c[i + 2], c[i + 3], u);
}

double CatmullRomSpline::SegmentArcLength(int segment, double u) const {
  // int_0^u |p'(v)| dv, composite Gauss-Legendre: on [a, b], v = m + h x with m the midpoint
  // and h the half-width, so the integral is h * sum_k w_k |p'(m + h x_k)|.
  const auto& c = control_points_;
  const double h = 0.5 * u / kQuadratureIntervals;
  double sum = 0.0;
  for (int j = 0; j < kQuadratureIntervals; ++j) {
    const double m = (2 * j + 1) * h;
    for (int k = 0; k < 5; ++k) {
      const double v = m + h * kGaussNodes[k];
      sum += kGaussWeights[k] * SegmentDerivative<double>(c[segment], c[segment + 1],
                                                          c[segment + 2], c[segment + 3], v)
                                    .norm();
    }
  }
  return h * sum;
}

double CatmullRomSpline::ArcLengthAt(double s) const {
  int i = 0;
  double u = 0.0;
  Locate(s, &i, &u);
  return cumulative_length_[i] + SegmentArcLength(i, u);
}

double CatmullRomSpline::ParameterAtArcLength(double arc_m) const {
  if (std::isnan(arc_m)) throw std::invalid_argument("CatmullRomSpline: NaN arc length");
  if (arc_m <= 0.0) return 0.0;
  if (arc_m >= Length()) return NumSegments();
  // Segment i with cumulative_length_[i] <= arc_m < cumulative_length_[i + 1].
  const int i = std::clamp(static_cast<int>(std::upper_bound(cumulative_length_.begin(),
                                                             cumulative_length_.end(), arc_m) -
                                            cumulative_length_.begin()) -
                               1,
                           0, NumSegments() - 1);
  const double target = arc_m - cumulative_length_[i];
  const double segment_length = cumulative_length_[i + 1] - cumulative_length_[i];
  if (segment_length <= 0.0) return i;
  // Solve L(u) = target with Newton (L'(u) = |p'(u)|), safeguarded by the bracket [lo, hi]
  // that always contains the root since L is monotone.
  double lo = 0.0, hi = 1.0;
  double u = target / segment_length;
  const auto& c = control_points_;
  for (int iteration = 0; iteration < 50; ++iteration) {
    const double f = SegmentArcLength(i, u) - target;
    if (std::abs(f) < 1e-10) break;
    (f > 0.0 ? hi : lo) = u;
    const double speed = SegmentDerivative<double>(c[i], c[i + 1], c[i + 2], c[i + 3], u).norm();
    double next = speed > 1e-12 ? u - f / speed : 0.5 * (lo + hi);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    u = next;
  }
  return i + u;
}

std::vector<Eigen::Vector3d> CatmullRomSpline::SampleByArcLength(double spacing_m) const {
  const std::vector<double> parameters = SampleParametersByArcLength(spacing_m);
  std::vector<Eigen::Vector3d> samples;
  samples.reserve(parameters.size());
  for (double s : parameters) samples.push_back(Evaluate(s));
  return samples;
}

std::vector<double> CatmullRomSpline::SampleParametersByArcLength(double spacing_m) const {
  if (!(spacing_m > 0.0) || !std::isfinite(spacing_m)) {
    throw std::invalid_argument("CatmullRomSpline::SampleByArcLength: spacing must be > 0");
  }
  const double length = Length();
  if (!std::isfinite(length)) {
    throw std::invalid_argument("CatmullRomSpline::SampleByArcLength: the length is not finite");
  }
  // Regular samples strictly before the end (a sample within 1e-9 m of it would duplicate it).
  // The count is computed in double and bounded before any conversion to int.
  double spacing = spacing_m;
  double wanted = std::ceil(length / spacing - 1e-9);
  if (wanted > kMaxArcLengthSamples) {
    spacing = length / kMaxArcLengthSamples;
    wanted = kMaxArcLengthSamples;
  }
  const int count = std::max(0, static_cast<int>(wanted));
  std::vector<double> parameters;
  parameters.reserve(static_cast<std::size_t>(count) + 1);
  for (int k = 0; k < count; ++k) parameters.push_back(ParameterAtArcLength(k * spacing));
  parameters.push_back(NumSegments());
  return parameters;
}

double CatmullRomSpline::MinimizeInBracket(int segment, const Eigen::Vector3d& query, double u,
                                           double* a, double* b) const {
  // Minimizes g(u) = |p(u) - q|^2 / 2 on [a, b]: g' = (p - q).p', g'' = |p'|^2 + (p - q).p''.
  // A Newton step is taken when g'' > 0 and it stays inside the bracket, which shrinks by the
  // sign of g' at every iterate; otherwise the bracket is bisected.
  const auto& c = control_points_;
  const Eigen::Vector3d a2 =
      2.0 * c[segment] - 5.0 * c[segment + 1] + 4.0 * c[segment + 2] - c[segment + 3];
  const Eigen::Vector3d a3 = 3.0 * (c[segment + 1] - c[segment + 2]) + c[segment + 3] - c[segment];
  for (int iteration = 0; iteration < kNewtonIterations; ++iteration) {
    const Eigen::Vector3d d =
        EvaluateSegment<double>(c[segment], c[segment + 1], c[segment + 2], c[segment + 3], u) -
        query;
    const Eigen::Vector3d dp =
        SegmentDerivative<double>(c[segment], c[segment + 1], c[segment + 2], c[segment + 3], u);
    const Eigen::Vector3d ddp = a2 + 3.0 * a3 * u;  // 0.5 * (2 a2 + 6 a3 u)
    const double g1 = d.dot(dp);
    const double g2 = dp.squaredNorm() + d.dot(ddp);
    if (g1 > 0.0) {
      *b = u;
    } else if (g1 < 0.0) {
      *a = u;
    } else {
      break;
    }
    double next = g2 > 0.0 ? u - g1 / g2 : 0.5 * (*a + *b);
    if (!(next > *a && next < *b)) next = 0.5 * (*a + *b);
    if (std::abs(next - u) < 1e-13 || *b - *a < 1e-13) {
      u = next;
      break;
    }
    u = next;
  }
  return u;
}

double CatmullRomSpline::SquaredDistance(int segment, double u,
                                         const Eigen::Vector3d& query) const {
  const auto& c = control_points_;
  return (EvaluateSegment<double>(c[segment], c[segment + 1], c[segment + 2], c[segment + 3], u) -
          query)
      .squaredNorm();
}

CatmullRomSpline::ClosestPoint CatmullRomSpline::FindClosest(const Eigen::Vector3d& query) const {
  // 1) Coarse: per segment, the best of its precomputed samples (step <= ~0.25 m of arc).
  //    A segment whose lower bound |query - center| - radius (its bounding sphere) exceeds
  //    the best sample so far cannot hold a closer point and is skipped; the segment of the
  //    smallest bound goes first, so that the bound prunes nearly all others (a linear scan,
  //    no sort: long lanes have hundreds of segments). 2) A visited segment can only beat the
  //    best coarse sample d* if its own best sample d_i satisfies d_i - step_i <= d* (any
  //    curve point lies within one step of a sample), so only those are refined. 3) Refine by
  //    golden-section search on the bracket of the two neighboring samples; the bracket ends
  //    are candidates too, which makes queries beyond the ends land exactly on them.
  struct Coarse {
    int segment;
    double distance;
    double u;
  };
  const int n = NumSegments();
  std::vector<double> lower_bound(n);
  int first = 0;
  for (int i = 0; i < n; ++i) {
    lower_bound[i] = (query - samples_[i].center).norm() - samples_[i].radius;
    if (lower_bound[i] < lower_bound[first]) first = i;
  }
  std::vector<Coarse> coarse;
  double best_coarse = std::numeric_limits<double>::infinity();
  auto visit = [&](int i) {
    const SegmentSamples& samples = samples_[i];
    Coarse best{i, std::numeric_limits<double>::infinity(), 0.0};
    for (std::size_t k = 0; k < samples.points.size(); ++k) {
      const double d = (samples.points[k] - query).norm();
      if (d < best.distance) {
        best.distance = d;
        best.u = static_cast<double>(k) * samples.step_u;
      }
    }
    best_coarse = std::min(best_coarse, best.distance);
    coarse.push_back(best);
  };
  if (n > 0) visit(first);
  for (int i = 0; i < n; ++i) {
    if (i != first && lower_bound[i] <= best_coarse) visit(i);
  }
  // Segment order as in a plain scan, so that ties resolve to the lower segment.
  std::sort(coarse.begin(), coarse.end(),
            [](const Coarse& a, const Coarse& b) { return a.segment < b.segment; });

  ClosestPoint result;
  double best_squared = std::numeric_limits<double>::infinity();
  for (const Coarse& candidate : coarse) {
    const int i = candidate.segment;
    const SegmentSamples& samples = samples_[i];
    // 1.5 x the chord between samples bounds the arc between them for gentle curves.
    if (candidate.distance - 1.5 * samples.step_m > best_coarse) continue;
    double a = std::max(0.0, candidate.u - samples.step_u);
    double b = std::min(1.0, candidate.u + samples.step_u);
    const double bracket_a = a, bracket_b = b;
    const double u_min = MinimizeInBracket(i, query, candidate.u, &a, &b);
    const double candidates[3] = {bracket_a, u_min, bracket_b};
    for (double u : candidates) {
      const double f = SquaredDistance(i, u, query);
      if (f < best_squared) {
        best_squared = f;
        result.segment = i;
        result.u = u;
      }
    }
  }
  result.s = result.segment + result.u;
  const auto& c = control_points_;
  const int i = result.segment;
  result.point = EvaluateSegment<double>(c[i], c[i + 1], c[i + 2], c[i + 3], result.u);
  result.distance_m = (result.point - query).norm();
  return result;
}

bool ControlPointRangeNear(const std::vector<Eigen::Vector3d>& control_points,
                           const std::vector<Eigen::Vector3d>& points, double margin_m,
                           std::size_t* first, std::size_t* last) {
  if (control_points.size() < 4 || points.empty()) return false;
  Eigen::Vector2d lo = points.front().head<2>(), hi = lo;
  for (const Eigen::Vector3d& p : points) {
    lo = lo.cwiseMin(p.head<2>());
    hi = hi.cwiseMax(p.head<2>());
  }
  lo.array() -= margin_m;
  hi.array() += margin_m;
  std::size_t a = control_points.size(), b = 0;
  for (std::size_t j = 0; j < control_points.size(); ++j) {
    const Eigen::Vector2d c = control_points[j].head<2>();
    if ((c.array() >= lo.array()).all() && (c.array() <= hi.array()).all()) {
      a = std::min(a, j);
      b = std::max(b, j);
    }
  }
  if (a == control_points.size()) return false;
  *first = a > 0 ? a - 1 : 0;
  *last = std::min(control_points.size() - 1, b + 1);
  // A curve of at least 4 points: widen at whichever end can.
  while (*last - *first + 1 < 4) {
    if (*first > 0) {
      --*first;
    } else if (*last + 1 < control_points.size()) {
      ++*last;
    } else {
      return false;
    }
  }
  return true;
}

double LaneEndCurvature(const std::vector<Eigen::Vector3d>& cps, bool at_end, double length_m) {
  const int n = static_cast<int>(cps.size());
  if (n < 5) return 0.0;
  const int end = at_end ? n - 2 : 1, step = at_end ? -1 : 1;
  int mid = end, far = end;
  double travelled = 0.0;
  while (far + step >= 1 && far + step <= n - 2 && travelled < length_m) {
    travelled += (cps[far + step] - cps[far]).head<2>().norm();
    far += step;
    if (travelled < 0.5 * length_m) mid = far;
  }
  if (mid == end || mid == far || travelled < 1e-6) return 0.0;
  const Eigen::Vector2d u = (cps[mid] - cps[far]).head<2>(), v = (cps[end] - cps[mid]).head<2>();
  const double turn = std::atan2(u.x() * v.y() - u.y() * v.x(), u.dot(v));
  return (at_end ? turn : -turn) / (0.5 * travelled);  // walked backwards from a start
}

}  // namespace ipm_road_mapper
