// Growing a lane's spline as the vehicle drives: the ends of the control-point estimator g
// ("extend the ends as new points arrive", docs/design.md §4). g (spline_fitting.h) starts a lane
// from one observation; every later frame hands the points of the lane's recent
// observations to FitLaneEnds, which
//  1. extends an end by whole chord spacings when enough points lie beyond it (along the
//     end tangent, within max_point_distance_m of its line), new control points placed
//     straight ahead, or along an arc of a given curvature (LaneEndCurvatures: the mapper
//     passes the driven path's, so that an end on a curve grows along the line);
//  2. re-estimates, by robust linear least squares, the real control points of the segments
//     the points fall on; the rest of the lane is held exactly.
// Step 2, with the points' curve parameters u_i (closest points) held fixed, is linear in
// the control points: each point gives p(u_i) = sum_j b_j(u_i) c_(s_i + j) (the Catmull-Rom
// basis of catmull_rom_spline.h), the phantom ends are c_0 = 2 c_1 - c_2 and
// c_(n-1) = 2 c_(n-2) - c_(n-3) (so the curve's end tangents follow the data), and
//   min  sum_i w_i |p(u_i) - q_i|^2 + lambda sum_j |c_(j-1) - 2 c_j + c_(j+1)|^2
//            + sum_j |c_j - c_j^prev|^2 / sigma^2
// over the free points, with Huber weights w_i (re-weighted twice). x, y and z share the
// same normal matrix (the basis is scalar), so it is one small m x m solve for 3 right-hand
// sides. The second differences keep the control points evenly spaced along the curve and
// bridge the gaps of dashed lines; the prior holds points that few samples reach.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace ipm_road_mapper {

// Parameters of FitLaneEnds (config section `lanes`; chord spacing is g's).
struct LaneEndFitOptions {
  double chord_spacing_m = 3.0;       // spacing of new control points (g's chord spacing)
  int min_points_to_extend = 5;       // points beyond an end needed to grow it
  double max_point_distance_m = 1.5;  // points farther from the curve (or end line) are ignored
  double smoothness_weight = 1.0;     // lambda, per second difference (m^-2 relative to a point)
  double prior_sigma_m = 1.0;         // pull of each free control point to its current value
  double robust_scale_m = 0.3;        // Huber scale of the point residuals
  double extension_weight = 0.1;      // weight of the growth points in the fit (see below)
};

// Signed horizontal curvatures (1/m, left turns positive, in the lane's start-to-end
// direction) of the arcs along which the lane's start and end grow. 0: straight ahead along
// the last chord. With a curvature, an end's tangent is its last chord turned by half the
// chord's angle, the points beyond it are measured along and across that arc, and the new
// control points lie on it.
struct LaneEndCurvatures {
  double at_start = 0.0;
  double at_end = 0.0;
};

// Extends and refines a lane's control points (phantom ends included, >= 4) with `points`
// (map frame, the lane's recent observations). Returns the new control points; control
// points that no point reaches are returned bit for bit, in place, and new ones are only
// appended at the ends, so an interior control point keeps its index relative to the old
// first one shifted by *added_at_start (if given). Non-finite points are ignored. Throws
// std::invalid_argument when control_points has fewer than 4 points.
// `extension_points` (when given) decide the growth of step 1 instead of `points`, and join
// the fit of step 2 with extension_weight: the mapper grows a lane with every point of low
// enough IPM uncertainty but fits it to the selected ones (point selection keeps the
// nearest, which never reach past the end; new control points need data all the same).
std::vector<Eigen::Vector3d> FitLaneEnds(
    const std::vector<Eigen::Vector3d>& control_points, const std::vector<Eigen::Vector3d>& points,
    const LaneEndFitOptions& options, int* added_at_start = nullptr,
    const std::vector<Eigen::Vector3d>* extension_points = nullptr,
    const LaneEndCurvatures& curvatures = LaneEndCurvatures());

// FitLaneEnds(*control_points, points, options, added_at_start, &extension_points) in place,
// on the part of the lane near the points only: a lane can be kilometers long, and a frame
// changes only its stretch near the recent observations (and grows an end there), so the
// cost does not grow with the lane. The result is the whole-lane result (FitLaneEnds holds
// every control point no point reaches); the whole lane is fit when the part would differ.
// *first_changed (if given): the index from which points may have changed (0: any).
void FitLaneEndsNear(const LaneEndFitOptions& options, const std::vector<Eigen::Vector3d>& points,
                     const std::vector<Eigen::Vector3d>& extension_points,
                     std::vector<Eigen::Vector3d>* control_points, int* added_at_start,
                     std::size_t* first_changed = nullptr,
                     const LaneEndCurvatures& curvatures = LaneEndCurvatures());

}  // namespace ipm_road_mapper
