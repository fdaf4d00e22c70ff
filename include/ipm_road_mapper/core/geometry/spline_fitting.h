// The control-point estimator g of the paper (g(tau(P))): from an unordered, noisy 3D point set
// of one lane line to Catmull-Rom control points at a fixed chord spacing. (A lane's ends are
// grown as new points arrive by FitLaneEnds, lane_end_fit.h.)
//
// Method (details in spline_fitting.cpp):
//  1. Order: project the points on their principal axis in x-y (PCA); this is the first
//     curve coordinate t.
//  2. Smooth: fit a curve f(t) sampled on a fine node grid by penalized least squares,
//       min_f  sum_i w_i |p_i - f(t_i)|^2 / rho  +  l^6 * integral |f'''(t)|^2 dt,
//     (rho: inlier weight per meter, l: smoothing length). The third-derivative penalty leaves
//     quadratics (circular arcs to 4th order) unbiased, bridges gaps of dashed lines and acts
//     locally (over a few l), so long lanes of changing curvature are followed.
//  3. Iterate: re-parameterize each point by arc length at its projection on the fitted
//     curve, and re-weight with Tukey's biweight of its distance to the curve (outliers get 0).
//  4. Place control points every chord spacing of arc length from the first inlier, the last
//     one at the last inlier (a remainder below half a spacing is merged into the last full
//     interval), and add phantom end points by linear extrapolation, c_0 = 2 c_1 - c_2.
//
// One call must see a lane turning by less than ~150 degrees (the PCA order must not fold);
// longer lanes are grown at their ends with FitLaneEnds.
//
// Direction convention: EstimateControlPoints orders control points by increasing projection
// on the principal axis, whose sign is chosen so that its x component is positive (its y
// component when x is 0).
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

namespace ipm_road_mapper {

// Parameters of the control-point estimator g.
struct SplineFitOptions {
  double chord_spacing_m = 3.0;     // distance between consecutive control points along the curve
  int min_points = 5;               // fewer input points -> no fit
  double min_extent_m = 1.0;        // shorter extent along the lane -> no fit
  double smoothing_length_m = 4.0;  // l: scale over which noise is averaged (~2-3 l window)
};

// g: unordered noisy 3D lane points -> control points at chord spacing. The returned spline
// (phantom end control points included) covers the points' full extent along the lane.
// Non-finite points are ignored. Returns nullopt when fewer than min_points (inlier) points or
// an extent below min_extent_m remain. Deterministic for a given input. Throws
// std::invalid_argument unless chord_spacing_m > 0, smoothing_length_m > 0, min_extent_m >= 0.
std::optional<std::vector<Eigen::Vector3d>> EstimateControlPoints(
    const std::vector<Eigen::Vector3d>& points, const SplineFitOptions& options);

}  // namespace ipm_road_mapper
