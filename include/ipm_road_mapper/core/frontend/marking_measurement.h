// Re-measuring a marking's corner pixels on a known road plane.
//
// The front end measures a marking's bounding rectangle on base_link's z = 0 plane (plain
// IPM) and projects its corners back into the image. On a road that is not that plane the
// measurement is biased: a rectangle on a plane tilted by 0.9 deg against base_link (body
// pitch, waves) maps to a keystone on z = 0, whose bounding rectangle is wider than the
// marking at one end, and its back-projected corners miss the true ones by several pixels.
// Supporting lines are projective invariants, so the same construction on the true plane is
// exact: map the outline's pixels onto the plane (ray-plane intersection), take the
// rectangle along the marking's axis in that plane, project its corners back. The back end
// does this with the road plane it knows best (the base_link plane of the frame closest to
// the marking, once the vehicle has driven past it).
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <vector>

#include "ipm_road_mapper/core/geometry/pinhole_camera.h"
#include "ipm_road_mapper/core/geometry/road_surface.h"

namespace ipm_road_mapper {

// The corner pixels of a marking observation (outline_uv, seen by the camera at T_map_cam)
// on `plane`, its rectangle's sides along axis_map (the road's direction, projected into the
// plane) and across it, returned in the order of reference_corners_map (best cyclic
// match). The axis must come from outside the marking: any axis gives a rectangle that
// every view agrees with, so the marking's own estimate would keep whatever orientation it
// started with. False when an outline ray misses the plane (at or above its horizon), the
// axis is along the normal or the outline is empty. A corner behind the camera (the cut
// corner of a partial view) is returned as NaN: callers use only the finite ones.
bool MeasureCornersOnPlane(const PinholeCamera& camera, const Eigen::Isometry3d& T_map_cam,
                           const RoadPlane& plane, const Eigen::Vector3d& axis_map,
                           const std::array<Eigen::Vector3d, 4>& reference_corners_map,
                           const std::vector<Eigen::Vector2d>& outline_uv,
                           std::array<Eigen::Vector2d, 4>* corners_uv);

}  // namespace ipm_road_mapper
