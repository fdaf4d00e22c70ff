// export_map: writes the GeoJSON and the Lanelet2 OSM of a map that was saved without them
// (mapped with no geo_origin in the config, or autosaved live), once its place on the Earth
// is known; or again, with another origin.
//
//   rosrun ipm_road_mapper export_map --map map.json [--geo-origin LAT,LON[,ALT[,HEADING]]]
//       [--out <folder>]
//
// The origin is --geo-origin, else the one the map recorded; without either nothing is
// written (local metres are not WGS84). The files go beside the map by the map files' rule
// (<stem>.geojson, <stem>.osm; pipeline/map_files.h), or into --out as map.geojson and map.osm.
// Exit codes: 0 success (or --help), 2 bad input (bad command line or origin, missing or
// malformed map; one line on stderr), 1 any other failure (a file cannot be written).
#include <cmath>
#include <filesystem>
#include <iostream>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "ipm_road_mapper/core/io/geojson_export.h"
#include "ipm_road_mapper/core/io/lanelet2_export.h"
#include "ipm_road_mapper/core/map/vector_map.h"
#include "ipm_road_mapper/pipeline/command_line.h"
#include "ipm_road_mapper/pipeline/map_files.h"

namespace {

using ipm_road_mapper::GeoOrigin;

// A bad --geo-origin (exit 2, like a bad command line).
struct BadOrigin : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct Arguments {
  std::string map_path;
  std::string geo_origin;  // empty: the map's
  std::string out;         // empty: beside the map
};

std::optional<int> ParseArguments(int argc, char** argv, Arguments* args) {
  ipm_road_mapper::CommandLine line(
      "export_map",
      "Writes the GeoJSON and the Lanelet2 OSM of a saved map (docs/map_from_bag.md) at a "
      "geographic origin.");
  line.Required("map", "<map.json>", &args->map_path, "the map (map_from_bag's map.json)")
      .Optional("geo-origin", "<lat,lon[,alt[,heading]]>", &args->geo_origin,
                "the origin the map recorded",
                "where the map frame's origin is: WGS84 degrees, altitude above the ellipsoid "
                "(m, default 0), heading of the map x axis from east (deg, default 0)")
      .Optional("out", "<folder>", &args->out, "beside the map",
                "folder for map.geojson and map.osm");
  return line.ParseOrExitCode(argc, argv);
}

// "lat,lon[,alt[,heading]]", each in the range the config's geo_origin accepts.
GeoOrigin ParseOrigin(const std::string& text) {
  std::vector<double> values;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    std::size_t used = 0;
    double value = 0.0;
    try {
      value = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || item.find_first_not_of(" \t", used) != std::string::npos ||
        !std::isfinite(value)) {
      throw BadOrigin("--geo-origin: '" + item + "' is not a number");
    }
    values.push_back(value);
  }
  if (values.size() < 2 || values.size() > 4) {
    throw BadOrigin("--geo-origin: expected lat,lon[,alt[,heading]], got '" + text + "'");
  }
  GeoOrigin origin;
  origin.latitude_deg = values[0];
  origin.longitude_deg = values[1];
  if (values.size() > 2) origin.altitude_m = values[2];
  if (values.size() > 3) origin.heading_deg = values[3];
  if (std::abs(origin.latitude_deg) > 90.0)
    throw BadOrigin("--geo-origin: latitude not in [-90, 90]");
  if (std::abs(origin.longitude_deg) > 180.0) {
    throw BadOrigin("--geo-origin: longitude not in [-180, 180]");
  }
  if (std::abs(origin.heading_deg) > 360.0) {
    throw BadOrigin("--geo-origin: heading not in [-360, 360]");
  }
  return origin;
}

int Run(int argc, char** argv) {
  using namespace ipm_road_mapper;
  Arguments args;
  if (const std::optional<int> exit_code = ParseArguments(argc, argv, &args)) return *exit_code;
  const std::optional<GeoOrigin> given =
      args.geo_origin.empty() ? std::nullopt
                              : std::optional<GeoOrigin>(ParseOrigin(args.geo_origin));
  const VectorMap map = LoadVectorMapJson(args.map_path);
  const std::optional<GeoOrigin> origin = given ? given : map.geo_origin;
  if (!origin) {
    throw BadOrigin(args.map_path +
                    " records no geo_origin: pass --geo-origin (local metres are not WGS84)");
  }
  if (!args.out.empty()) std::filesystem::create_directories(args.out);
  const MapFilePaths paths =
      args.out.empty() ? MapFilePathsFor(args.map_path) : MapFilePathsInFolder(args.out);
  Lanelet2ExportStats stats;
  SaveGeoJson(map, origin, paths.geojson);
  SaveLanelet2Osm(map, *origin, paths.osm, &stats);
  std::cout << "origin: " << origin->latitude_deg << ", " << origin->longitude_deg << ", "
            << origin->altitude_m << " m, heading " << origin->heading_deg << " deg ("
            << (given ? "--geo-origin" : "recorded in the map") << ")\n"
            << "wrote " << paths.geojson << " (" << map.markings.size() << " markings, "
            << map.lanes.size() << " lanes)\n"
            << "wrote " << paths.osm << " (" << stats.lanelets << " lanelets, " << stats.ways
            << " ways, " << stats.nodes << " nodes"
            << (stats.lanes_left_out > 0
                    ? "; " + std::to_string(stats.lanes_left_out) + " lanes left out"
                    : std::string())
            << ")\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return Run(argc, argv);
  } catch (const BadOrigin& e) {
    std::cerr << "export_map: error: " << e.what() << "\n";
  } catch (const ipm_road_mapper::MapFormatError& e) {
    std::cerr << "export_map: error: " << e.what() << "\n";
  } catch (const std::exception& e) {
    std::cerr << "export_map: error: " << e.what() << "\n";
    return 1;
  }
  return 2;
}
