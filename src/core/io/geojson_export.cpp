#include "ipm_road_mapper/core/io/geojson_export.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "ipm_road_mapper/core/io/map_geodesy.h"
#include "json_io.h"

namespace ipm_road_mapper {
namespace {

constexpr double kDegreeScale = 1e9;  // rounded to 1e-9 deg, ~0.1 mm on the Earth
constexpr double kMetricScale = 1e4;  // rounded to 0.1 mm

// Rounds to 1 / scale. Dividing the rounded integer by the power of ten gives the double
// nearest to the decimal, so the JSON shows 18.0097 rather than 18.009700000000002.
double Round(double value, double scale) { return std::round(value * scale) / scale + 0.0; }

nlohmann::json Rounded(const Eigen::Vector3d& v, double scale) {
  return nlohmann::json::array({Round(v.x(), scale), Round(v.y(), scale), Round(v.z(), scale)});
}
constexpr int kGeoJsonIndent = 1;

// Map-frame points -> GeoJSON positions, local or geographic.
class PositionConverter {
 public:
  explicit PositionConverter(const std::optional<GeoOrigin>& origin) {
    if (origin) to_wgs84_.emplace(*origin);
  }

  // [lon, lat, alt] with an origin, else [x, y, z].
  nlohmann::json Position(const Eigen::Vector3d& p_map) const {
    if (!to_wgs84_) return Rounded(p_map, kMetricScale);
    const Wgs84Point p = to_wgs84_->Convert(p_map);
    return nlohmann::json::array({Round(p.longitude_deg, kDegreeScale),
                                  Round(p.latitude_deg, kDegreeScale),
                                  Round(p.altitude_m, kMetricScale)});
  }

  const char* CoordinateSystem() const {
    return to_wgs84_ ? kCoordinateSystemWgs84 : kCoordinateSystemLocal;
  }

 private:
  std::optional<MapToWgs84> to_wgs84_;
};

// Twice the signed area of the polygon's x-y projection (> 0: counter-clockwise from above).
double SignedArea2(const std::array<Eigen::Vector3d, 4>& corners) {
  double area2 = 0.0;
  for (std::size_t i = 0; i < corners.size(); ++i) {
    const Eigen::Vector3d& a = corners[i];
    const Eigen::Vector3d& b = corners[(i + 1) % corners.size()];
    area2 += a.x() * b.y() - b.x() * a.y();
  }
  return area2;
}

nlohmann::json MarkingFeature(const MapMarking& marking, const PositionConverter& converter) {
  // East/north map axes keep their orientation in lon/lat, so a ring that is
  // counter-clockwise in the map frame is counter-clockwise in the output too.
  std::vector<Eigen::Vector3d> ring(marking.corners_map.begin(), marking.corners_map.end());
  if (SignedArea2(marking.corners_map) < 0.0) std::reverse(ring.begin() + 1, ring.end());
  ring.push_back(ring.front());
  nlohmann::json positions = nlohmann::json::array();
  for (const Eigen::Vector3d& p_map : ring) positions.push_back(converter.Position(p_map));

  nlohmann::json properties = {{"id", marking.id},
                               {"class_name", marking.class_name},
                               {"class_id", marking.class_id},
                               {"kind", "marking"},
                               {"style", nullptr},
                               {"observations", marking.observations},
                               {"first_seen", marking.first_seen},
                               {"last_seen", marking.last_seen},
                               {"coordinate_system", converter.CoordinateSystem()}};
  return {{"type", "Feature"},
          {"id", marking.id},
          {"geometry", {{"type", "Polygon"}, {"coordinates", nlohmann::json::array({positions})}}},
          {"properties", properties}};
}

nlohmann::json LaneFeature(const MapLane& lane, const PositionConverter& converter) {
  nlohmann::json control_points = nlohmann::json::array();
  for (const Eigen::Vector3d& c_map : lane.control_points_map) {
    control_points.push_back(Rounded(c_map, kMetricScale));
  }
  // The control points no pixel measured, as in map.json.
  nlohmann::json unmeasured = nlohmann::json::array();
  for (const auto& [first, last] : lane.unmeasured) unmeasured.push_back({first, last});
  nlohmann::json geometry = nullptr;
  const std::vector<Eigen::Vector3d> polyline = LanePolyline(lane, kLaneSampleSpacing_m);
  if (polyline.size() >= 2) {
    nlohmann::json positions = nlohmann::json::array();
    for (const Eigen::Vector3d& p_map : polyline) positions.push_back(converter.Position(p_map));
    geometry = {{"type", "LineString"}, {"coordinates", positions}};
  }
  nlohmann::json properties = {
      {"id", lane.id},
      {"class_name", lane.class_name},
      {"class_id", lane.class_id},
      {"kind", "lane"},
      {"style", lane.style.empty() ? nlohmann::json(nullptr) : nlohmann::json(lane.style)},
      {"observations", lane.observations},
      {"first_seen", lane.first_seen},
      {"last_seen", lane.last_seen},
      {"control_points", control_points},
      {"unmeasured", unmeasured},
      {"coordinate_system", converter.CoordinateSystem()}};
  return {{"type", "Feature"}, {"id", lane.id}, {"geometry", geometry}, {"properties", properties}};
}

}  // namespace

nlohmann::json VectorMapToGeoJson(const VectorMap& map, const std::optional<GeoOrigin>& origin) {
  const PositionConverter converter(origin);
  nlohmann::json features = nlohmann::json::array();
  for (const MapMarking& marking : map.markings) {
    features.push_back(MarkingFeature(marking, converter));
  }
  for (const MapLane& lane : map.lanes) features.push_back(LaneFeature(lane, converter));
  // Foreign members (allowed by RFC 7946 §6.1): how to read the positions.
  nlohmann::json collection = {{"type", "FeatureCollection"},
                               {"coordinate_system", converter.CoordinateSystem()},
                               {"frame_id", map.frame_id}};
  if (origin) {
    collection["geo_origin"] = {{"latitude_deg", origin->latitude_deg},
                                {"longitude_deg", origin->longitude_deg},
                                {"altitude_m", origin->altitude_m},
                                {"heading_deg", origin->heading_deg}};
  }
  collection["features"] = std::move(features);
  return collection;
}

void SaveGeoJson(const VectorMap& map, const std::optional<GeoOrigin>& origin,
                 const std::string& path) {
  json_io::WriteFileAtomically(path, VectorMapToGeoJson(map, origin).dump(kGeoJsonIndent) + "\n");
}

std::optional<GeoOrigin> LoadGeoOrigin(OptionsReader reader) {
  const bool any_key = reader.Has("latitude_deg") || reader.Has("longitude_deg") ||
                       reader.Has("altitude_m") || reader.Has("heading_deg");
  auto in_range = [](double limit) {
    return [limit](const double& v) -> std::string {
      return std::isfinite(v) && std::abs(v) <= limit
                 ? ""
                 : "must be in [-" + std::to_string(static_cast<int>(limit)) + ", " +
                       std::to_string(static_cast<int>(limit)) + "]";
    };
  };
  GeoOrigin origin;
  if (any_key) {
    reader.ReadRequired<double>("latitude_deg", &origin.latitude_deg, in_range(90.0));
    reader.ReadRequired<double>("longitude_deg", &origin.longitude_deg, in_range(180.0));
  }
  reader.Read<double>("altitude_m", &origin.altitude_m, [](const double& v) -> std::string {
    return std::isfinite(v) ? "" : "must be finite";
  });
  reader.Read<double>("heading_deg", &origin.heading_deg, in_range(360.0));
  reader.RejectUnknownKeys();
  if (!any_key) return std::nullopt;
  return origin;
}

}  // namespace ipm_road_mapper
