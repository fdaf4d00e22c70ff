#include "ipm_road_mapper/core/io/map_geodesy.h"

#include <cmath>
#include <stdexcept>

#include "ipm_road_mapper/core/map/lane_samples.h"

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

std::vector<Eigen::Vector3d> LanePolyline(const MapLane& lane, double spacing_m,
                                          std::vector<bool>* unmeasured) {
  const std::size_t n = lane.control_points_map.size();
  if (unmeasured) unmeasured->clear();
  if (n >= 4) {
    try {
      LaneSamples samples =
          SampleLane(lane.control_points_map, UnmeasuredPointFlags(lane), spacing_m);
      if (unmeasured) *unmeasured = std::move(samples.unmeasured);
      return std::move(samples.points);
    } catch (const std::invalid_argument&) {
      return {};  // a non-finite control point: no geometry rather than a broken one
    }
  }
  if (n >= 2) {
    if (unmeasured) *unmeasured = UnmeasuredPointFlags(lane);
    return lane.control_points_map;
  }
  return {};
}

}  // namespace ipm_road_mapper
