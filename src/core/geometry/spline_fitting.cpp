#include "ipm_road_mapper/core/geometry/spline_fitting.h"

#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "ipm_road_mapper/core/geometry/principal_axis.h"

namespace ipm_road_mapper {
namespace {

// Smoothing passes (solve, re-parameterize, re-weight). The first pass runs on the PCA
// projection with unit weights; later ones on arc length with robust weights.
constexpr int kPasses = 5;
// Largest node step of the fitted polyline; its chord error is step^2 / (8 R) = 0.6 mm at
// R = 50 m.
constexpr double kMaxNodeStepM = 0.5;
// A point's projection is searched within this distance (in the previous curve coordinate)
// of its previous coordinate, so a curve that bends back on itself is never confused.
constexpr double kSearchWindowM = 5.0;
// Tukey biweight cutoff in units of the noise scale (95% efficiency for Gaussian noise).
constexpr double kTukeyCutoff = 4.685;
// The noise scale is never taken below this, so clean synthetic data keeps its points.
constexpr double kMinNoiseSigmaM = 0.02;
// Median of the distance to the curve of 2D isotropic Gaussian noise (Rayleigh) in sigmas.
constexpr double kRayleighMedian = 1.1774;

// A smooth lane curve as a fine polyline, with the extent of the fit's inliers.
struct LaneCurve {
  std::vector<Eigen::Vector3d> nodes;
  std::vector<double> arc;  // arc length at each node, arc[0] = 0
  double begin = 0.0;       // arc coordinate of the first inlier
  double end = 0.0;         // arc coordinate of the last inlier

  // Point at arc coordinate a; linear extrapolation along the end segments beyond the ends.
  Eigen::Vector3d At(double a) const {
    const int last = static_cast<int>(nodes.size()) - 2;
    const int k = std::clamp(
        static_cast<int>(std::upper_bound(arc.begin(), arc.end(), a) - arc.begin()) - 1, 0, last);
    const double length = arc[k + 1] - arc[k];
    if (length <= 0.0) return nodes[k];
    return nodes[k] + (a - arc[k]) / length * (nodes[k + 1] - nodes[k]);
  }
};

// Projection of p on segments [k_lo, k_hi] of the polyline (nodes, arc); the first and last
// segments of the whole polyline extend beyond their ends. Returns the arc coordinate and sets
// *distance.
double ProjectOnPolyline(const std::vector<Eigen::Vector3d>& nodes, const std::vector<double>& arc,
                         const Eigen::Vector3d& p, int k_lo, int k_hi, double* distance) {
  const int last = static_cast<int>(nodes.size()) - 2;
  double best_arc = arc[std::clamp(k_lo, 0, last)];
  double best_squared = std::numeric_limits<double>::infinity();
  for (int k = std::max(k_lo, 0); k <= std::min(k_hi, last); ++k) {
    const Eigen::Vector3d segment = nodes[k + 1] - nodes[k];
    const double length_squared = segment.squaredNorm();
    double alpha = length_squared > 0.0 ? (p - nodes[k]).dot(segment) / length_squared : 0.0;
    alpha = std::min(alpha, k == last ? std::numeric_limits<double>::infinity() : 1.0);
    alpha = std::max(alpha, k == 0 ? -std::numeric_limits<double>::infinity() : 0.0);
    const double d2 = (nodes[k] + alpha * segment - p).squaredNorm();
    if (d2 < best_squared) {
      best_squared = d2;
      best_arc = arc[k] + alpha * std::sqrt(length_squared);
    }
  }
  *distance = std::sqrt(best_squared);
  return best_arc;
}

// Initial curve coordinate: projection on the principal axis of the points in x-y, with the
// axis oriented to positive x (positive y when x is 0).
std::vector<double> PrincipalAxisCoordinates(const std::vector<Eigen::Vector3d>& points) {
  const PrincipalAxis principal = HorizontalPrincipalAxis(points);
  const Eigen::Vector2d& mean = principal.mean;
  Eigen::Vector2d axis = principal.direction;
  if (axis.x() < 0.0 || (axis.x() == 0.0 && axis.y() < 0.0)) axis = -axis;
  std::vector<double> t;
  t.reserve(points.size());
  for (const Eigen::Vector3d& p : points) t.push_back(axis.dot(p.head<2>() - mean));
  return t;
}

// Penalized least squares on nodes f_k = f(t0 + k h), k = 0..K, with point i interpolated
// linearly between its two nodes (row b_i of B):
//   min  sum_i w_i |b_i F - p_i|^2 + mu sum_k |f_k - 3 f_{k+1} + 3 f_{k+2} - f_{k+3}|^2,
// the discrete form of sum_i w_i |f(t_i) - p_i|^2 / rho + l^6 int |f'''|^2 dt times rho, since
// f''' ~ (third difference) / h^3 and dt = h: mu = rho l^6 / h^5. Normal equations
// (B^T W B + mu D^T D) F = B^T W P: a banded positive definite system (7 diagonals).
bool SolveSmoother(const std::vector<Eigen::Vector3d>& centered, const std::vector<double>& t,
                   const std::vector<double>& w, double t0, double h, int K, double mu,
                   std::vector<Eigen::Vector3d>* nodes) {
  std::vector<Eigen::Triplet<double>> triplets;
  Eigen::MatrixX3d rhs = Eigen::MatrixX3d::Zero(K + 1, 3);
  for (size_t i = 0; i < centered.size(); ++i) {
    if (w[i] <= 0.0) continue;
    const double x = (t[i] - t0) / h;
    const int k = std::clamp(static_cast<int>(std::floor(x)), 0, K - 1);
    const double a = x - k;  // weights (1 - a, a) on nodes k, k + 1
    const double b[2] = {1.0 - a, a};
    for (int r = 0; r < 2; ++r) {
      rhs.row(k + r) += w[i] * b[r] * centered[i].transpose();
      for (int c = 0; c < 2; ++c) triplets.emplace_back(k + r, k + c, w[i] * b[r] * b[c]);
    }
  }
  const double d[4] = {1.0, -3.0, 3.0, -1.0};
  for (int k = 0; k + 3 <= K; ++k) {
    for (int r = 0; r < 4; ++r) {
      for (int c = 0; c < 4; ++c) triplets.emplace_back(k + r, k + c, mu * d[r] * d[c]);
    }
  }
  Eigen::SparseMatrix<double> A(K + 1, K + 1);
  A.setFromTriplets(triplets.begin(), triplets.end());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(A);
  if (ldlt.info() != Eigen::Success) return false;
  const Eigen::MatrixX3d F = ldlt.solve(rhs);
  if (ldlt.info() != Eigen::Success || !F.allFinite()) return false;
  nodes->resize(K + 1);
  for (int k = 0; k <= K; ++k) (*nodes)[k] = F.row(k).transpose();
  return true;
}

// The median of `values` (copied, partially sorted).
double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + mid, values.end());
  return values[mid];
}

// Steps 1-3 of the method: order, smooth, iterate with re-parameterization and re-weighting.
// Requires finite points; returns nullopt when the fit is degenerate or too small.
std::optional<LaneCurve> FitLaneCurve(const std::vector<Eigen::Vector3d>& points,
                                      const SplineFitOptions& options) {
  const size_t n = points.size();
  if (n < static_cast<size_t>(std::max(options.min_points, 3))) return std::nullopt;
  // Centering keeps the normal equations well scaled for map coordinates far from the origin.
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : points) centroid += p;
  centroid /= static_cast<double>(n);
  std::vector<Eigen::Vector3d> centered(n);
  for (size_t i = 0; i < n; ++i) centered[i] = points[i] - centroid;

  LaneCurve curve;
  std::vector<double> t = PrincipalAxisCoordinates(points);
  std::vector<double> w(n, 1.0);
  std::vector<double> residual(n, 0.0);
  for (int pass = 0; pass < kPasses; ++pass) {
    double t_lo = std::numeric_limits<double>::infinity(), t_hi = -t_lo, weight_sum = 0.0;
    for (size_t i = 0; i < n; ++i) {
      if (w[i] <= 0.0) continue;
      t_lo = std::min(t_lo, t[i]);
      t_hi = std::max(t_hi, t[i]);
      weight_sum += w[i];
    }
    const double extent = t_hi - t_lo;
    if (!(extent > 1e-6)) return std::nullopt;
    const int K = std::max(4, static_cast<int>(std::ceil(extent / kMaxNodeStepM)));
    const double h = extent / K;
    // A smoothing length beyond the extent changes nothing (the fit is already a quadratic)
    // and would only worsen the conditioning.
    const double l = std::min(options.smoothing_length_m, extent);
    const double mu = weight_sum / extent * std::pow(l, 6) / std::pow(h, 5);
    if (!SolveSmoother(centered, t, w, t_lo, h, K, mu, &curve.nodes)) return std::nullopt;
    curve.arc.assign(K + 1, 0.0);
    for (int k = 0; k < K; ++k) {
      curve.arc[k + 1] = curve.arc[k] + (curve.nodes[k + 1] - curve.nodes[k]).norm();
    }
    // Re-parameterize by arc length at the projection on the new curve.
    const int window = static_cast<int>(std::ceil(kSearchWindowM / h));
    for (size_t i = 0; i < n; ++i) {
      const int k = std::clamp(static_cast<int>(std::floor((t[i] - t_lo) / h)), 0, K - 1);
      t[i] = ProjectOnPolyline(curve.nodes, curve.arc, centered[i], k - window, k + window,
                               &residual[i]);
    }
    // Re-weight: Tukey's biweight of the distance to the curve, on a robust noise scale.
    const double sigma = std::max(kMinNoiseSigmaM, Median(residual) / kRayleighMedian);
    const double cutoff = kTukeyCutoff * sigma;
    for (size_t i = 0; i < n; ++i) {
      const double x = residual[i] / cutoff;
      w[i] = x < 1.0 ? (1.0 - x * x) * (1.0 - x * x) : 0.0;
    }
  }
  for (Eigen::Vector3d& node : curve.nodes) node += centroid;
  curve.begin = std::numeric_limits<double>::infinity();
  curve.end = -curve.begin;
  int inliers = 0;
  for (size_t i = 0; i < n; ++i) {
    if (w[i] <= 0.0) continue;
    ++inliers;
    curve.begin = std::min(curve.begin, t[i]);
    curve.end = std::max(curve.end, t[i]);
  }
  if (inliers < options.min_points || !(curve.end - curve.begin >= options.min_extent_m) ||
      !(curve.end > curve.begin)) {
    return std::nullopt;
  }
  return curve;
}

// Curve points from arc coordinate `from` to `to` (> from): one every `spacing` of arc length,
// then `to`. A remainder below half a spacing is merged into the last full interval (a very
// short interval would make the uniform Catmull-Rom overshoot), so every interval but the last
// is exactly `spacing` and the last is in [spacing / 2, 3 spacing / 2) (or the whole length).
std::vector<Eigen::Vector3d> PlaceAlong(const LaneCurve& curve, double from, double to,
                                        double spacing) {
  const double length = to - from;
  const int full = static_cast<int>(std::floor(length / spacing + 1e-9));
  const double remainder = length - full * spacing;
  std::vector<double> offsets;
  for (int k = 0; k <= full; ++k) offsets.push_back(k * spacing);
  if (full == 0 || remainder >= 0.5 * spacing) {
    offsets.push_back(length);
  } else {
    offsets.back() = length;
  }
  std::vector<Eigen::Vector3d> placed;
  for (double offset : offsets) placed.push_back(curve.At(from + offset));
  return placed;
}

// Adds the phantom end points by linear extrapolation: c_0 = 2 c_1 - c_2 (and likewise at the
// end), which makes the end tangent the end chord, p'(0) = (c_2 - c_0) / 2 = c_2 - c_1.
std::vector<Eigen::Vector3d> WithPhantoms(const std::vector<Eigen::Vector3d>& on_curve) {
  std::vector<Eigen::Vector3d> control_points;
  control_points.reserve(on_curve.size() + 2);
  control_points.push_back(2.0 * on_curve[0] - on_curve[1]);
  control_points.insert(control_points.end(), on_curve.begin(), on_curve.end());
  control_points.push_back(2.0 * on_curve.back() - on_curve[on_curve.size() - 2]);
  return control_points;
}

// The finite points of `points`, in their order.
std::vector<Eigen::Vector3d> FinitePoints(const std::vector<Eigen::Vector3d>& points) {
  std::vector<Eigen::Vector3d> finite;
  finite.reserve(points.size());
  for (const Eigen::Vector3d& p : points) {
    if (p.allFinite()) finite.push_back(p);
  }
  return finite;
}

// Throws std::invalid_argument on options the fit cannot run with.
void CheckOptions(const SplineFitOptions& options) {
  if (!(options.chord_spacing_m > 0.0) || !(options.smoothing_length_m > 0.0) ||
      !(options.min_extent_m >= 0.0)) {
    throw std::invalid_argument(
        "SplineFitOptions: chord_spacing_m and smoothing_length_m must be > 0, "
        "min_extent_m >= 0");
  }
}

}  // namespace

std::optional<std::vector<Eigen::Vector3d>> EstimateControlPoints(
    const std::vector<Eigen::Vector3d>& points, const SplineFitOptions& options) {
  CheckOptions(options);
  const std::optional<LaneCurve> curve = FitLaneCurve(FinitePoints(points), options);
  if (!curve) return std::nullopt;
  return WithPhantoms(PlaceAlong(*curve, curve->begin, curve->end, options.chord_spacing_m));
}

}  // namespace ipm_road_mapper
