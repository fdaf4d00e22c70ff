// The road under and ahead of the vehicle, from its recent trajectory: the front end's ground
// (what IPM maps pixels onto) instead of base_link's plane z = 0.
//
// base_link rests on the road but pitches and rolls with the body on its suspension (0.3 deg
// in the synthetic drives; a real car more when it brakes). Flat-ground IPM in base_link
// then tilts the whole ground with the body: a point 25 m ahead seen by a camera 1.5 m up
// lands 25^2 * 0.0052 / 1.5 = 2.2 m off along the road, and a line 3.5 m to the side 0.3 m
// off across it. The road itself does not pitch with the body, and the trajectory knows it:
// - the grade is the slope of the path's height over the last `grade_length_m` of path
//   (a least-squares line of the heights against the distance travelled), which neither the
//   body's pitch nor its heave (averaged over the fit) enter;
// - the cross slope is the body's roll averaged over the last `cross_slope_window_s` (the
//   path has no lateral extent; the suspension's roll averages out).
// The plane passes through base_link's origin (on the road under the vehicle) and is
// extrapolated ahead. With an odometry that reports a flat 2D pose (z and roll/pitch zero)
// it is base_link's plane z = 0 exactly.
#pragma once

#include <Eigen/Geometry>
#include <vector>

#include "ipm_road_mapper/core/geometry/rigid_transform.h"
#include "ipm_road_mapper/core/geometry/road_surface.h"

namespace ipm_road_mapper {

// How the road plane is estimated from the trajectory (config section `ipm`).
struct TrajectoryRoadPlaneOptions {
  double grade_length_m = 30.0;       // path behind the vehicle whose heights give the grade
  double cross_slope_window_s = 1.5;  // the body's roll is averaged over this long
};

// Below this much path (m) within grade_length_m (a standing or creeping vehicle) the grade
// is not fit: the plane is the body's mean attitude over the cross-slope window.
constexpr double kMinGradePathM = 1.0;

// The road plane in the newest pose's base_link (through its origin, normal up). `recent`
// holds the trajectory oldest first, the newest pose last; the poses older than both windows
// are not used. An empty trajectory gives base_link's plane z = 0.
RoadPlane RoadPlaneFromTrajectory(const std::vector<StampedPose>& recent,
                                  const TrajectoryRoadPlaneOptions& options);

}  // namespace ipm_road_mapper
