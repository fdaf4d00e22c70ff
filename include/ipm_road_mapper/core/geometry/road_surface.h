// The road's surface near a map point, as the vehicle's poses know it. base_link's origin is
// on the road and its z axis is the road's normal, up to the body's pitch and roll
// oscillation on its suspension (0.3 deg here, 1.3 cm over half a 5 m marking, which a
// camera looking along the road turns into 13 cm along it). The frames that drove within a
// radius of the point are averaged, which averages that oscillation out; a point no frame
// has passed yet gets the closest frame's plane, extrapolated.
#pragma once

#include <Eigen/Geometry>
#include <vector>

#include "ipm_road_mapper/core/geometry/pinhole_camera.h"

namespace ipm_road_mapper {

// A plane in the map frame: n . (p - point) = 0, n of unit length, pointing up.
struct RoadPlane {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
};

// The plane near p_map and how far it is extrapolated.
struct RoadSurfaceEstimate {
  RoadPlane plane;
  double distance_m = 0.0;  // horizontal distance from p_map to the closest frame used
  double lateral_m = 0.0;   // p_map's offset along that frame's base_link y (left > 0)
  int frames = 0;           // frames averaged (0: no pose at all)
};

// Averages the base_link planes (mean origin, mean z axis) of the poses within radius_m of
// p_map horizontally, or takes the closest pose's when none is that close.
RoadSurfaceEstimate RoadSurfaceNear(const std::vector<Eigen::Isometry3d>& T_map_base,
                                    const Eigen::Vector3d& p_map, double radius_m);

// The same estimate from poses already selected: `within` (the poses within the radius, in
// frame order; may be empty) and the closest pose with its horizontal distance.
RoadSurfaceEstimate RoadSurfaceFromPoses(const std::vector<const Eigen::Isometry3d*>& within,
                                         const Eigen::Isometry3d& T_map_base_closest,
                                         double closest_distance_m, const Eigen::Vector3d& p_map);

// Where the ray of pixel uv from the camera at T_map_cam meets `plane` (normal up) ahead of the
// camera: *p_map. False for a non-finite pixel, a ray that does not descend to the plane (at
// or above its horizon) or one that meets it behind the camera.
bool PixelOntoPlane(const PinholeCamera& camera, const Eigen::Isometry3d& T_map_cam,
                    const RoadPlane& plane, const Eigen::Vector2d& uv, Eigen::Vector3d* p_map);

}  // namespace ipm_road_mapper
