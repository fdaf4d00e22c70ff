#include "ipm_road_mapper/core/io/map_geodesy.h"

#include <cmath>
#include <stdexcept>

#include "ipm_road_mapper/core/geometry/catmull_rom_spline.h"

namespace ipm_road_mapper {

MapToWgs84::MapToWgs84(const GeoOrigin& origin)
    : local_cartesian_(origin.latitude_deg, origin.longitude_deg, origin.altitude_m),
      cos_heading_(std::cos(origin.heading_deg * M_PI / 180.0)),
      sin_heading_(std::sin(origin.heading_deg * M_PI / 180.0)) {}

Wgs84Point MapToWgs84::Convert(const Eigen::Vector3d& p_map) const {
  const double east = cos_heading_ * p_map.x() - sin_heading_ * p_map.y();
  const double north = sin_heading_ * p_map.x() + cos_heading_ * p_map.y();
  Wgs84Point p;
  local_cartesian_.Reverse(east, north, p_map.z(), p.latitude_deg, p.longitude_deg, p.altitude_m);
  return p;
}

std::vector<Eigen::Vector3d> LanePolyline(const MapLane& lane, double spacing_m) {
  if (lane.control_points_map.size() >= 4) {
    try {
      return CatmullRomSpline(lane.control_points_map).SampleByArcLength(spacing_m);
    } catch (const std::invalid_argument&) {
      return {};  // a non-finite control point: no geometry rather than a broken one
    }
  }
  if (lane.control_points_map.size() >= 2) return lane.control_points_map;
  return {};
}

}  // namespace ipm_road_mapper
