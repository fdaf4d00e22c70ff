// GeoJSON export: RFC 7946 structure, closed counter-clockwise rings, lanes as sampled
// splines, geographic positions near the origin, the local-coordinates flag, the atomic
// file and the `geo_origin` config section.
#include <gtest/gtest.h>
#include <unistd.h>

#include <GeographicLib/Geodesic.hpp>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "ipm_road_mapper/core/geometry/catmull_rom_spline.h"
#include "ipm_road_mapper/core/io/geojson_export.h"

namespace ipm_road_mapper {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// A 4 m x 2 m marking whose corners are given clockwise (seen from above), and a straight
// 20 m lane along x at y = 3.5 m.
VectorMap SmallMap(double offset_x = 0.0) {
  VectorMap map;
  MapMarking marking;
  marking.id = 7;
  marking.class_id = 10;
  marking.class_name = "arrow_straight";
  marking.observations = 5;
  marking.corners_map = {Eigen::Vector3d(offset_x + 0, 0, 0), Eigen::Vector3d(offset_x + 0, 2, 0),
                         Eigen::Vector3d(offset_x + 4, 2, 0), Eigen::Vector3d(offset_x + 4, 0, 0)};
  map.markings.push_back(marking);
  MapLane lane;
  lane.id = 8;
  lane.class_id = 2;
  lane.class_name = "lane_white_dashed";
  lane.style = "dashed";
  lane.observations = 12;
  for (int i = -1; i <= 5; ++i) lane.control_points_map.emplace_back(5.0 * i, 3.5, 0.1);
  map.lanes.push_back(lane);
  return map;
}

// Twice the signed area of a GeoJSON ring (positions [a, b, ...], first == last).
double RingArea2(const json& ring) {
  double area2 = 0.0;
  for (std::size_t i = 0; i + 1 < ring.size(); ++i) {
    area2 += ring[i][0].get<double>() * ring[i + 1][1].get<double>() -
             ring[i + 1][0].get<double>() * ring[i][1].get<double>();
  }
  return area2;
}

GeoOrigin Munich() { return {48.0, 11.0, 500.0}; }

TEST(GeoJsonExportTest, IsAFeatureCollectionOfPolygonsAndLineStrings) {
  const json j = VectorMapToGeoJson(SmallMap(), std::nullopt);
  EXPECT_EQ(j.at("type"), "FeatureCollection");
  ASSERT_EQ(j.at("features").size(), 2u);
  EXPECT_FALSE(j.contains("crs")) << "RFC 7946 removed crs";
  for (const json& feature : j.at("features")) {
    EXPECT_EQ(feature.at("type"), "Feature");
    EXPECT_TRUE(feature.at("properties").is_object());
    for (const char* key : {"id", "class_name", "class_id", "kind", "style", "observations"}) {
      EXPECT_TRUE(feature.at("properties").contains(key)) << key;
    }
  }
  const json& marking = j["features"][0];
  EXPECT_EQ(marking["geometry"]["type"], "Polygon");
  EXPECT_EQ(marking["properties"]["kind"], "marking");
  EXPECT_EQ(marking["properties"]["class_name"], "arrow_straight");
  EXPECT_EQ(marking["properties"]["class_id"], 10);
  EXPECT_EQ(marking["properties"]["observations"], 5);
  EXPECT_EQ(marking["properties"]["id"], 7);
  const json& lane = j["features"][1];
  EXPECT_EQ(lane["geometry"]["type"], "LineString");
  EXPECT_EQ(lane["properties"]["kind"], "lane");
  EXPECT_EQ(lane["properties"]["style"], "dashed");
  ASSERT_EQ(lane["properties"]["control_points"].size(), 7u);
  EXPECT_EQ(lane["properties"]["control_points"][1], json::array({0.0, 3.5, 0.1}));
}

TEST(GeoJsonExportTest, MarkingRingIsClosedAndCounterClockwise) {
  const json j = VectorMapToGeoJson(SmallMap(), std::nullopt);
  const json& rings = j["features"][0]["geometry"]["coordinates"];
  ASSERT_EQ(rings.size(), 1u);  // exterior ring only
  const json& ring = rings[0];
  ASSERT_EQ(ring.size(), 5u);
  EXPECT_EQ(ring.front(), ring.back());
  EXPECT_GT(RingArea2(ring), 0.0) << "the input was clockwise; the output must not be";
  EXPECT_NEAR(RingArea2(ring), 2.0 * 8.0, 1e-9);
  EXPECT_EQ(ring[0], json::array({0.0, 0.0, 0.0}));  // starts at the same corner

  // An already counter-clockwise marking keeps its corner order.
  VectorMap ccw = SmallMap();
  std::swap(ccw.markings[0].corners_map[1], ccw.markings[0].corners_map[3]);
  const json ring_ccw =
      VectorMapToGeoJson(ccw, std::nullopt)["features"][0]["geometry"]["coordinates"][0];
  EXPECT_EQ(ring_ccw[1], json::array({4.0, 0.0, 0.0}));
  EXPECT_GT(RingArea2(ring_ccw), 0.0);
}

TEST(GeoJsonExportTest, LaneIsTheSplineSampledEveryHalfMeter) {
  const json j = VectorMapToGeoJson(SmallMap(), std::nullopt);
  const json& line = j["features"][1]["geometry"]["coordinates"];
  // The curve runs from the second control point (x = 0) to the second to last (x = 20).
  ASSERT_EQ(line.size(), 41u);
  EXPECT_NEAR(line.front()[0].get<double>(), 0.0, 1e-6);
  EXPECT_NEAR(line.back()[0].get<double>(), 20.0, 1e-6);
  for (std::size_t i = 1; i < line.size(); ++i) {
    EXPECT_NEAR(line[i][0].get<double>() - line[i - 1][0].get<double>(), 0.5, 1e-3);
    EXPECT_NEAR(line[i][1].get<double>(), 3.5, 1e-9);
  }
}

TEST(GeoJsonExportTest, ALanesUnmeasuredControlPointsAreAProperty) {
  VectorMap map = SmallMap();
  EXPECT_EQ(VectorMapToGeoJson(map, std::nullopt)["features"][1]["properties"]["unmeasured"],
            json::array());
  map.lanes[0].unmeasured = {{2, 3}};
  EXPECT_EQ(VectorMapToGeoJson(map, std::nullopt)["features"][1]["properties"]["unmeasured"],
            json::parse("[[2, 3]]"));
}

TEST(GeoJsonExportTest, ShortLanesDegradeGracefully) {
  VectorMap map = SmallMap();
  map.lanes[0].control_points_map.resize(2);
  json j = VectorMapToGeoJson(map, std::nullopt);
  EXPECT_EQ(j["features"][1]["geometry"]["coordinates"].size(), 2u);
  map.lanes[0].control_points_map.resize(1);
  j = VectorMapToGeoJson(map, std::nullopt);
  EXPECT_TRUE(j["features"][1]["geometry"].is_null());  // an unlocated feature (RFC 7946 3.2)
}

TEST(GeoJsonExportTest, WithoutOriginFlagsLocalMetricCoordinates) {
  const json j = VectorMapToGeoJson(SmallMap(), std::nullopt);
  EXPECT_EQ(j["coordinate_system"], "local_metric_enu_m");
  EXPECT_FALSE(j.contains("geo_origin"));
  for (const json& feature : j["features"]) {
    EXPECT_EQ(feature["properties"]["coordinate_system"], "local_metric_enu_m");
  }
}

TEST(GeoJsonExportTest, WithOriginPositionsAreLonLatAltNearTheOrigin) {
  VectorMap map;
  MapMarking marking;
  marking.id = 1;
  // A small square around the point 100 m east of the origin, 2 m up.
  marking.corners_map = {Eigen::Vector3d(99, -1, 2), Eigen::Vector3d(101, -1, 2),
                         Eigen::Vector3d(101, 1, 2), Eigen::Vector3d(99, 1, 2)};
  map.markings.push_back(marking);
  MapLane lane;
  lane.id = 2;
  for (int i = -1; i <= 2; ++i) lane.control_points_map.emplace_back(0.0, 100.0 * i, 0.0);
  map.lanes.push_back(lane);

  const json j = VectorMapToGeoJson(map, Munich());
  EXPECT_EQ(j["coordinate_system"], "wgs84");
  EXPECT_DOUBLE_EQ(j["geo_origin"]["latitude_deg"].get<double>(), 48.0);
  const json& ring = j["features"][0]["geometry"]["coordinates"][0];
  double lon = 0.0, lat = 0.0, alt = 0.0;
  for (std::size_t i = 0; i < 4; ++i) {
    lon += 0.25 * ring[i][0].get<double>();
    lat += 0.25 * ring[i][1].get<double>();
    alt += 0.25 * ring[i][2].get<double>();
  }
  // 100 m east at 48 deg N: 100 / (cos(48 deg) * 111.3 km/deg) = 0.00134 deg of longitude.
  EXPECT_NEAR(lon - 11.0, 0.00134, 0.00001);
  EXPECT_NEAR(lat, 48.0, 1e-6);
  EXPECT_NEAR(alt, 502.0, 0.01);
  EXPECT_GT(RingArea2(ring), 0.0) << "counter-clockwise in lon/lat as well";
  // The lane runs north from the origin: 100 m is about 0.0009 deg of latitude.
  const json& line = j["features"][1]["geometry"]["coordinates"];
  EXPECT_NEAR(line.front()[0].get<double>(), 11.0, 1e-9);
  EXPECT_NEAR(line.front()[1].get<double>(), 48.0, 1e-9);
  EXPECT_NEAR(line.back()[1].get<double>() - 48.0, 100.0 / 111200.0, 0.00001);
  // Control points stay local so the spline can be rebuilt.
  EXPECT_EQ(j["features"][1]["properties"]["control_points"][1], json::array({0.0, 0.0, 0.0}));
}

TEST(GeoJsonExportTest, TheHeadingTurnsTheMapFrameIntoEastNorthUp) {
  // A lane along the map's x axis; the map frame's x points north (heading 90 deg).
  VectorMap map;
  MapLane lane;
  lane.id = 2;
  for (int i = -1; i <= 2; ++i) lane.control_points_map.emplace_back(100.0 * i, 0.0, 0.0);
  map.lanes.push_back(lane);
  GeoOrigin origin = Munich();
  origin.heading_deg = 90.0;
  const json j = VectorMapToGeoJson(map, origin);
  EXPECT_DOUBLE_EQ(j["geo_origin"]["heading_deg"].get<double>(), 90.0);
  const json& line = j["features"][0]["geometry"]["coordinates"];
  EXPECT_NEAR(line.back()[0].get<double>(), 11.0, 1e-9);                        // no move east
  EXPECT_NEAR(line.back()[1].get<double>() - 48.0, 100.0 / 111200.0, 0.00001);  // 100 m north
  // Heading 0: the map frame is ENU, x east.
  origin.heading_deg = 0.0;
  const json enu = VectorMapToGeoJson(map, origin)["features"][0]["geometry"]["coordinates"];
  EXPECT_NEAR(enu.back()[1].get<double>(), 48.0, 1e-6);
  EXPECT_GT(enu.back()[0].get<double>(), 11.001);
}

// Geodesic length (m, on the WGS84 ellipsoid) of a LineString's [lon, lat, alt] positions.
double GeodesicLength_m(const json& line) {
  const GeographicLib::Geodesic& wgs84 = GeographicLib::Geodesic::WGS84();
  double length_m = 0.0;
  for (std::size_t i = 0; i + 1 < line.size(); ++i) {
    double segment_m = 0.0;
    wgs84.Inverse(line[i][1].get<double>(), line[i][0].get<double>(), line[i + 1][1].get<double>(),
                  line[i + 1][0].get<double>(), segment_m);
    length_m += segment_m;
  }
  return length_m;
}

// With an origin, a GIS reader measures the lanes as long as the map (and the evaluator,
// which sums the splines' arc lengths) does: the bug was local metres read as degrees.
TEST(GeoJsonExportTest, GeodesicLaneLengthMatchesTheMapsLaneLength) {
  VectorMap map;
  MapLane straight;  // 600 m east
  straight.id = 1;
  for (int i = -1; i <= 13; ++i) straight.control_points_map.emplace_back(50.0 * i, 0.0, 0.0);
  MapLane curve;  // a 400 m radius quarter circle
  curve.id = 2;
  for (int i = -1; i <= 11; ++i) {
    const double angle = 0.5 * M_PI * i / 10.0;
    curve.control_points_map.emplace_back(400.0 * std::cos(angle), 400.0 * std::sin(angle), 0.0);
  }
  map.lanes = {straight, curve};
  for (const GeoOrigin& origin : {Munich(), GeoOrigin{-33.9, 18.4, 10.0}, GeoOrigin{64.1, -21.9}}) {
    const json j = VectorMapToGeoJson(map, origin);
    double geojson_m = 0.0, map_m = 0.0;
    for (const MapLane& lane : map.lanes)
      map_m += CatmullRomSpline(lane.control_points_map).Length();
    for (const json& feature : j["features"]) {
      ASSERT_EQ(feature["geometry"]["type"], "LineString");
      geojson_m += GeodesicLength_m(feature["geometry"]["coordinates"]);
    }
    EXPECT_GT(map_m, 1200.0);
    EXPECT_NEAR(geojson_m, map_m, 0.01 * map_m) << "origin latitude " << origin.latitude_deg;
  }
}

TEST(GeoJsonExportTest, SaveWritesTheFileAtomically) {
  char pattern[] = "/tmp/irm_geojson_XXXXXX";
  ASSERT_NE(mkdtemp(pattern), nullptr);
  const std::string dir = pattern;
  const std::string path = dir + "/map.geojson";
  SaveGeoJson(SmallMap(), Munich(), path);
  std::ifstream in(path);
  const json j = json::parse(in);
  EXPECT_EQ(j, VectorMapToGeoJson(SmallMap(), Munich()));
  std::size_t files = 0;
  for (const auto& entry : fs::directory_iterator(dir)) files += entry.is_regular_file();
  EXPECT_EQ(files, 1u) << "no temporary file left behind";
  EXPECT_THROW(SaveGeoJson(SmallMap(), Munich(), dir + "/missing/map.geojson"), std::runtime_error);
  fs::remove_all(dir);
}

YAML::Node Yaml(const std::string& text) { return YAML::Load(text); }

TEST(GeoJsonExportTest, LoadGeoOrigin) {
  const auto origin = LoadGeoOrigin(OptionsReader(
      Yaml("{latitude_deg: 48.1, longitude_deg: 11.5, altitude_m: 520}"), "geo_origin"));
  ASSERT_TRUE(origin.has_value());
  EXPECT_DOUBLE_EQ(origin->latitude_deg, 48.1);
  EXPECT_DOUBLE_EQ(origin->longitude_deg, 11.5);
  EXPECT_DOUBLE_EQ(origin->altitude_m, 520.0);
  const auto no_altitude =
      LoadGeoOrigin(OptionsReader(Yaml("{latitude_deg: 48.1, longitude_deg: 11.5}"), "geo_origin"));
  ASSERT_TRUE(no_altitude.has_value());
  EXPECT_DOUBLE_EQ(no_altitude->altitude_m, 0.0);

  // Absent (the parent's Child() gives an empty map) or null: no origin.
  EXPECT_FALSE(LoadGeoOrigin(OptionsReader(YAML::Node(YAML::NodeType::Map), "geo_origin")));
  EXPECT_FALSE(LoadGeoOrigin(OptionsReader(YAML::Node(YAML::NodeType::Null), "geo_origin")));
}

TEST(GeoJsonExportTest, LoadGeoOriginRejectsBadSections) {
  auto error_of = [](const std::string& text) -> std::string {
    try {
      LoadGeoOrigin(OptionsReader(Yaml(text), "geo_origin"));
    } catch (const OptionsError& e) {
      return e.what();
    }
    return "no error";
  };
  EXPECT_EQ(error_of("{latitude_deg: 48.0}"), "geo_origin.longitude_deg: required key is missing");
  EXPECT_EQ(error_of("{latitude_deg: 91, longitude_deg: 0}"),
            "geo_origin.latitude_deg: must be in [-90, 90]");
  EXPECT_EQ(error_of("{latitude_deg: 48.0, longitude_deg: 11.0, heading_deg: 400}"),
            "geo_origin.heading_deg: must be in [-360, 360]");
  EXPECT_DOUBLE_EQ(LoadGeoOrigin(OptionsReader(Yaml("{latitude_deg: 48.0, longitude_deg: 11.0, "
                                                    "heading_deg: -12.5}"),
                                               "geo_origin"))
                       ->heading_deg,
                   -12.5);
  EXPECT_EQ(error_of("{latitude_deg: 0, longitude_deg: -181}"),
            "geo_origin.longitude_deg: must be in [-180, 180]");
  EXPECT_EQ(error_of("{latitude_deg: 0, longitude_deg: 0, lat: 3}"), "geo_origin.lat: unknown key");
  EXPECT_EQ(error_of("{lat: 3}"), "geo_origin.lat: unknown key");
  EXPECT_NE(error_of("{latitude_deg: north, longitude_deg: 0}").find("wrong type"),
            std::string::npos);
}

}  // namespace
}  // namespace ipm_road_mapper
