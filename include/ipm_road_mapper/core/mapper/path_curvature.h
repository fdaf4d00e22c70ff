// The driven path's curvature and the curvature of lines beside it: a lane line on a curve
// keeps its offset from the path the vehicle drives, so it turns about the path's center.
// The lane tracker grows a lane's ends along that arc (LaneEndCurvatures) instead of
// straight ahead along the end's last chord (docs/backend.md, "Growth along the path").
// The path's curvature comes from the poses' headings, not from the lane's far points
// (whose IPM bias the curvature of a lane's own control points carries).
#pragma once

#include <Eigen/Geometry>
#include <vector>

#include "ipm_road_mapper/core/geometry/lane_end_fit.h"
#include "ipm_road_mapper/core/map/road_map.h"

namespace ipm_road_mapper {

// The path's signed horizontal curvature (1/m, left turns positive) over its last
// `length_m` up to frame `index`: the heading change over the chord from the frame that
// far back. 0 when the path so far is shorter than half of that, or length_m is 0.
double PathCurvature(const std::vector<FrameRecord>& frames, std::size_t index, double length_m);

// The curvature of the line through `p_map` concentric with the path's arc (curvature
// `path_curvature` from the vehicle at T_map_base), signed along `direction` (the lane's
// start-to-end direction there). 0 for a line across the path (more than 45 deg from it).
double ConcentricCurvature(const Eigen::Isometry3d& T_map_base, double path_curvature,
                           const Eigen::Vector3d& p_map, const Eigen::Vector3d& direction);

// The curvatures along which a lane's start and end grow (FitLaneEnds) in frame `index`:
// each end's concentric curvature with the path's over `length_m` (0: straight growth),
// where it is at least `min_curvature` (below it the end grows straight).
LaneEndCurvatures PathEndCurvatures(const std::vector<FrameRecord>& frames, std::size_t index,
                                    double length_m, double min_curvature,
                                    const std::vector<Eigen::Vector3d>& control_points);

// The least curvature that needs the arc: an end grown straight on an arc of curvature
// kappa leaves the line by kappa L^2 / 2 at L past it, and association measures an
// observation up to `end_gap_m` past an end to its tangent line within `gate_m`: below
// 2 gate_m / end_gap_m^2 (1/94 m for 1.2 m and 15 m) the tangent keeps the line in the gate.
double MinGrowthCurvature(double gate_m, double end_gap_m);

}  // namespace ipm_road_mapper
