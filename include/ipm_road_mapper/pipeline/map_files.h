// Writing a finished map to disk, the same way for the offline runner (map_from_bag --out)
// and the nodelet (~save_map, and at shutdown): the map JSON, its GeoJSON and the corrected
// trajectory in TUM format, each written atomically by the core's writers. No ROS header.
#pragma once

#include <optional>
#include <string>

#include "ipm_road_mapper/core/io/geojson_export.h"
#include "ipm_road_mapper/core/map/vector_map.h"

namespace ipm_road_mapper {

// Where the three files of one map go.
struct MapFilePaths {
  std::string json;     // the map (docs/file_formats.md)
  std::string geojson;  // RFC 7946 export
  std::string tum;      // corrected T_map_base per used frame
};

// The files of a map saved as `json_path` (the ~save_map convention): "<stem>.json",
// "<stem>.geojson" and "<stem>_trajectory_tum.txt", where <stem> is json_path without a
// trailing ".json". Example: /tmp/m.json -> /tmp/m.geojson, /tmp/m_trajectory_tum.txt.
MapFilePaths MapFilePathsFor(const std::string& json_path);

// The files of map_from_bag's output folder: map.json, map.geojson, trajectory_tum.txt.
MapFilePaths MapFilePathsInFolder(const std::string& folder);

// Creates the parent folders and writes the three files. Throws std::runtime_error naming
// the file that could not be written.
void SaveMapFiles(const VectorMap& map, const std::optional<GeoOrigin>& geo_origin,
                  const MapFilePaths& paths);

}  // namespace ipm_road_mapper
