// Map-frame points on the Earth and lane splines as polylines: what the exports of the map
// (GeoJSON, Lanelet2 OSM) share.
//
// The map frame is taken to be ENU (x east, y north, z up, m) at a geographic origin turned
// by its heading (GeoOrigin, vector_map.h); a point is turned into east, north, up and then
// onto WGS84 by GeographicLib::LocalCartesian.Reverse (altitude above the ellipsoid).
#pragma once

#include <Eigen/Core>
#include <GeographicLib/LocalCartesian.hpp>
#include <vector>

#include "ipm_road_mapper/core/map/vector_map.h"

namespace ipm_road_mapper {

// Lane splines are sampled this often (arc length, m) in the exports' line strings.
constexpr double kLaneSampleSpacing_m = 0.5;

// A point on WGS84.
struct Wgs84Point {
  double latitude_deg = 0.0;
  double longitude_deg = 0.0;
  double altitude_m = 0.0;  // above the ellipsoid
};

// Map-frame points -> WGS84 (see the file comment).
class MapToWgs84 {
 public:
  explicit MapToWgs84(const GeoOrigin& origin);
  Wgs84Point Convert(const Eigen::Vector3d& p_map) const;

 private:
  GeographicLib::LocalCartesian local_cartesian_;
  double cos_heading_ = 1.0, sin_heading_ = 0.0;
};

// A lane's spline sampled every `spacing_m` of arc length (map frame). A lane with 2-3
// control points gives its control points, fewer (or a non-finite control point) nothing.
// With `unmeasured`, per sample whether it lies on a stretch no pixel measured (lane_samples.h).
std::vector<Eigen::Vector3d> LanePolyline(const MapLane& lane, double spacing_m,
                                          std::vector<bool>* unmeasured = nullptr);

}  // namespace ipm_road_mapper
