// Uniform Catmull-Rom spline (tension 0.5) through 3D control points c_0..c_{n-1}, n >= 4.
//
// Segment i (i = 0..n-4) runs from c_{i+1} to c_{i+2} and depends on c_i..c_{i+3}. With the
// four points of a segment named c0..c3 and the local parameter u in [0, 1]:
//
//   p(u) = 0.5 * [ 2 c1 + (-c0 + c2) u + (2 c0 - 5 c1 + 4 c2 - c3) u^2
//                  + (-c0 + 3 c1 - 3 c2 + c3) u^3 ]
//
// This is the cubic Hermite curve from c1 to c2 with end tangents p'(0) = (c2 - c0) / 2 and
// p'(1) = (c3 - c1) / 2, so consecutive segments share position and tangent (C1).
// Check: p(0) = c1; p(1) = 0.5 [2c1 - c0 + c2 + 2c0 - 5c1 + 4c2 - c3 - c0 + 3c1 - 3c2 + c3] = c2.
//
// The global parameter s in [0, n-3] names a point on the whole curve: segment floor(s) (the
// last segment for s = n-3), u = s - segment. Since ds = du, dp/ds = dp/du.
// The first and last control points c_0 and c_{n-1} are not on the curve ("phantom" points
// that only shape the end segments).
#pragma once

#include <Eigen/Core>
#include <vector>

namespace ipm_road_mapper {

// A uniform Catmull-Rom curve with arc-length tools and closest-point queries.
class CatmullRomSpline {
 public:
  // Result of a closest-point query: where on the curve, and how far away.
  struct ClosestPoint {
    double s = 0.0;                                   // global parameter, in [0, NumSegments()]
    int segment = 0;                                  // segment index, in [0, NumSegments() - 1]
    double u = 0.0;                                   // local parameter in the segment, in [0, 1]
    Eigen::Vector3d point = Eigen::Vector3d::Zero();  // the closest curve point
    double distance_m = 0.0;  // Euclidean distance from the query to `point`
  };

  // Takes the control points c_0..c_{n-1}. Throws std::invalid_argument when n < 4 or a
  // point is not finite.
  explicit CatmullRomSpline(std::vector<Eigen::Vector3d> control_points);

  // Number of curve segments, n - 3; also the largest global parameter s.
  int NumSegments() const { return static_cast<int>(control_points_.size()) - 3; }

  // The control points, phantom end points included.
  const std::vector<Eigen::Vector3d>& ControlPoints() const { return control_points_; }

  // Splits a global parameter (clamped to [0, NumSegments()]) into segment index and u.
  // Throws std::invalid_argument for NaN.
  void Locate(double s, int* segment, double* u) const;

  // Curve point at global parameter s (clamped to [0, NumSegments()]).
  Eigen::Vector3d Evaluate(double s) const;

  // Tangent dp/ds at global parameter s (clamped to [0, NumSegments()]).
  Eigen::Vector3d Derivative(double s) const;

  // Point of one segment from its four control points; templated so that Ceres autodiff
  // (T = ceres::Jet) can differentiate residuals with respect to the control points.
  template <typename T>
  static Eigen::Matrix<T, 3, 1> EvaluateSegment(const Eigen::Matrix<T, 3, 1>& c0,
                                                const Eigen::Matrix<T, 3, 1>& c1,
                                                const Eigen::Matrix<T, 3, 1>& c2,
                                                const Eigen::Matrix<T, 3, 1>& c3, const T& u) {
    // Horner form of 0.5 * [a0 + a1 u + a2 u^2 + a3 u^3] with the coefficients above.
    const Eigen::Matrix<T, 3, 1> a0 = T(2.0) * c1;
    const Eigen::Matrix<T, 3, 1> a1 = c2 - c0;
    const Eigen::Matrix<T, 3, 1> a2 = T(2.0) * c0 - T(5.0) * c1 + T(4.0) * c2 - c3;
    const Eigen::Matrix<T, 3, 1> a3 = T(3.0) * (c1 - c2) + c3 - c0;
    return T(0.5) * (a0 + (a1 + (a2 + a3 * u) * u) * u);
  }

  // dp/du of one segment: 0.5 * [a1 + 2 a2 u + 3 a3 u^2], the derivative of the basis above.
  template <typename T>
  static Eigen::Matrix<T, 3, 1> SegmentDerivative(const Eigen::Matrix<T, 3, 1>& c0,
                                                  const Eigen::Matrix<T, 3, 1>& c1,
                                                  const Eigen::Matrix<T, 3, 1>& c2,
                                                  const Eigen::Matrix<T, 3, 1>& c3, const T& u) {
    const Eigen::Matrix<T, 3, 1> a1 = c2 - c0;
    const Eigen::Matrix<T, 3, 1> a2 = T(2.0) * c0 - T(5.0) * c1 + T(4.0) * c2 - c3;
    const Eigen::Matrix<T, 3, 1> a3 = T(3.0) * (c1 - c2) + c3 - c0;
    return T(0.5) * (a1 + (T(2.0) * a2 + T(3.0) * a3 * u) * u);
  }

  // Total arc length in meters (Gauss-Legendre quadrature of |dp/ds|, exact to ~1e-9 m for
  // the gently curved segments of lanes).
  double Length() const { return cumulative_length_.back(); }

  // Arc length from the curve start to global parameter s (clamped).
  double ArcLengthAt(double s) const;

  // Global parameter at arc length arc_m from the start (clamped to [0, Length()]).
  double ParameterAtArcLength(double arc_m) const;

  // Most samples SampleByArcLength returns (plus the end point).
  static constexpr int kMaxArcLengthSamples = 1'000'000;

  // Points every spacing_m of arc length from the start, then the end point (so the last gap
  // may be shorter). A curve longer than kMaxArcLengthSamples * spacing_m is sampled at
  // Length() / kMaxArcLengthSamples instead, so the count (and memory) stays bounded.
  // Throws std::invalid_argument unless spacing_m > 0 and the length is finite.
  std::vector<Eigen::Vector3d> SampleByArcLength(double spacing_m) const;
  // The global parameters of those samples (same throws).
  std::vector<double> SampleParametersByArcLength(double spacing_m) const;

  // Global closest curve point to `query` over all segments. Queries beyond an end get that
  // end (s = 0 or s = NumSegments()). Segments whose bounding sphere is farther than the best
  // sample found so far are skipped, so a query costs about two segments' work on a long lane.
  ClosestPoint FindClosest(const Eigen::Vector3d& query) const;

 private:
  // A segment sampled on a regular u grid (built once, for closest-point queries).
  struct SegmentSamples {
    std::vector<Eigen::Vector3d> points;  // at u = k / (points.size() - 1)
    double step_u = 0.0;
    double step_m = 0.0;  // longest chord between consecutive samples
    Eigen::Vector3d center = Eigen::Vector3d::Zero();
    double radius = 0.0;  // every curve point is within this of center
  };

  // Arc length within `segment` from u = 0 to u.
  double SegmentArcLength(int segment, double u) const;
  // Local minimum of the distance to `query` over u in [*a, *b] of `segment`, started at u
  // (the bracket shrinks around it).
  double MinimizeInBracket(int segment, const Eigen::Vector3d& query, double u, double* a,
                           double* b) const;
  // Squared distance from `query` to the point of `segment` at u.
  double SquaredDistance(int segment, double u, const Eigen::Vector3d& query) const;

  std::vector<Eigen::Vector3d> control_points_;
  // cumulative_length_[i] = arc length from the start to the beginning of segment i;
  // cumulative_length_[NumSegments()] = Length().
  std::vector<double> cumulative_length_;
  std::vector<SegmentSamples> samples_;
};

// The control points of a long curve that matter near a region: [first, last] (inclusive
// indices) span every control point within margin_m (x-y) of the axis-aligned box around
// `points`, plus one on each side. A segment depends on its four control points only, so
// segment k of CatmullRomSpline(c[first..last]) is segment first + k of the whole curve,
// and with a margin above the control-point spacing every segment that passes through the
// box is among them.
// Queries near a region of a long lane (association, road direction) then cost what the
// region needs, not the lane's length. Returns false when fewer than 4 control points
// result (no part of the curve near the region, or a curve of < 4 points).
// Signed curvature (1/m, > 0 turning left along the points' order) of the curve through the
// control points near its end (at_end) or its start: the turn of its direction over about
// length_m of real control points, over half that length (a long baseline: over one chord a
// 0.1 m wobble of an end point reads as R 45 m). 0 with fewer than 5 control points.
double LaneEndCurvature(const std::vector<Eigen::Vector3d>& control_points, bool at_end,
                        double length_m);

bool ControlPointRangeNear(const std::vector<Eigen::Vector3d>& control_points,
                           const std::vector<Eigen::Vector3d>& points, double margin_m,
                           std::size_t* first, std::size_t* last);

}  // namespace ipm_road_mapper
