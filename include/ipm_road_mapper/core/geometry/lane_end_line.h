// Where a lane goes on past one of its ends: the line association measures an observation
// beyond the end against (association.h).
//
// The spline's own tangent at an end is the direction of its last chord, which the last
// real control point alone sets. That point is the least measured one of the lane: the
// newest data, a few frames, each off by the odometry's noise. At 0.5 m of per-pose noise
// it was 0.5 m off over a 3 m chord, a tangent 10 deg wrong, whose line 12 m past the end
// lay 2 m beside the lane, in the gate of the next line over: on public_road at 0.5 m
// noise a lane jumped to its neighbour's line past a crossing, where neither is painted.
//
// So the end's line is the least-squares line through the lane's real control points
// within `length_m` of the end (Catmull-Rom interpolates its control points: they are
// samples of the curve). In the frame of the end control point c_e, s along the chord from
// the farthest of them to c_e and l to its left, l(s) = a + b s. With two points (length_m
// under one chord) it is the last chord's line, the spline's own end tangent.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace ipm_road_mapper {

struct LaneEndLine {
  bool valid = false;
  Eigen::Vector2d origin = Eigen::Vector2d::Zero();    // the end control point c_e (x-y)
  Eigen::Vector2d forward = Eigen::Vector2d::UnitX();  // s: outward, past the end
  Eigen::Vector2d left = Eigen::Vector2d::UnitY();     // l: to the left of `forward`
  double offset_m = 0.0;                               // a
  double slope = 0.0;                                  // b

  // The line's unit direction, outward.
  Eigen::Vector2d Direction() const { return (forward + slope * left).normalized(); }
};

// The line past the last (`at_end`) or the first real control point of `control_points`
// (phantom ends included; invalid with fewer than 4 points or non-finite ones), fitted to
// the real control points within `length_m` of it (at least two).
LaneEndLine FitLaneEndLine(const std::vector<Eigen::Vector3d>& control_points, bool at_end,
                           double length_m);

// The distance (m, horizontal) of `p_map` from the line, and (if given) how far along it
// past the end, *along_m (negative: before the end).
double DistanceFromEndLine(const LaneEndLine& line, const Eigen::Vector3d& p_map, double* along_m);

}  // namespace ipm_road_mapper
