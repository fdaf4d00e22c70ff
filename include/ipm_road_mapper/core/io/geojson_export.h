// GeoJSON (RFC 7946) export of the vector map, for GIS tools (QGIS, geojson.io, shapely).
//
// A FeatureCollection with one Feature per map element:
// - a marking is a Polygon: its 4 corners as one closed linear ring (first position
//   repeated), counter-clockwise seen from above (the RFC 7946 right-hand rule for exterior
//   rings);
// - a lane is a LineString: its Catmull-Rom spline sampled every kLaneSampleSpacing_m of arc
//   length (a lane with 2-3 control points: the control points; fewer: "geometry": null);
// properties: id, class_name, class_id, kind ("marking" | "lane"), style, observations,
// first_seen, last_seen, coordinate_system, and for lanes control_points ([x, y, z] in the
// map frame, m, always local, so the spline can be rebuilt exactly).
//
// Coordinates. The map frame is taken to be ENU (x east, y north, z up, m) at a geographic
// origin (REP-105 `map`; an odometry `map` frame is not geo-referenced, so the origin is the
// user's statement of where the map frame's origin is and that it is aligned with east/north).
// - With a GeoOrigin: positions are [longitude_deg, latitude_deg, altitude_m] on WGS84
//   (altitude above the ellipsoid), computed by GeographicLib::LocalCartesian.Reverse; this
//   is plain RFC 7946 and "coordinate_system" is "wgs84".
// - Without one: positions are the local metric [x, y, z] and "coordinate_system" is
//   "local_metric_enu_m" (at the top level and in every feature's properties). RFC 7946
//   removed the `crs` member, so there is no standard way to say this: readers will treat
//   the numbers as degrees. Use it for plotting/inspection in a local frame only; the map
//   files (SaveMapFiles) never write a GeoJSON without an origin.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "ipm_road_mapper/core/io/map_geodesy.h"  // kLaneSampleSpacing_m
#include "ipm_road_mapper/core/io/yaml_options.h"
#include "ipm_road_mapper/core/map/vector_map.h"

namespace ipm_road_mapper {

// GeoOrigin (where the map frame's origin is on the Earth) is declared in vector_map.h.

// Values of the "coordinate_system" member/property.
constexpr const char* kCoordinateSystemLocal = "local_metric_enu_m";
constexpr const char* kCoordinateSystemWgs84 = "wgs84";

// The map as a GeoJSON FeatureCollection (see the file comment). Positions in degrees are
// rounded to 1e-9 deg (0.1 mm), metric ones to 0.1 mm.
nlohmann::json VectorMapToGeoJson(const VectorMap& map, const std::optional<GeoOrigin>& origin);

// Writes VectorMapToGeoJson(map, origin) atomically (temporary file + rename). Throws
// std::runtime_error when the file cannot be written.
void SaveGeoJson(const VectorMap& map, const std::optional<GeoOrigin>& origin,
                 const std::string& path);

// Reads the `geo_origin` section ({latitude_deg, longitude_deg, altitude_m}); an absent or
// empty section gives no origin. latitude_deg and longitude_deg are required when the
// section has any key; altitude_m defaults to 0. Throws OptionsError naming the bad key.
std::optional<GeoOrigin> LoadGeoOrigin(OptionsReader reader);

}  // namespace ipm_road_mapper
