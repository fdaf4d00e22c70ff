// Writing a finished map to disk, the same way for the offline runner (map_from_bag --out)
// and the nodelet (~save_map, the autosave and at shutdown): the map JSON, its GeoJSON and
// Lanelet2 OSM exports (only with a geo origin) and the corrected trajectory in TUM format,
// named by one rule (MapFilePathsFor). A save is atomic per file and all-or-nothing for the
// files: each is written and fsynced under a temporary name in its own folder first, then they
// are renamed into place. Also the rule that keeps a live map saved before a ~reset
// (MapSaveTarget). No ROS header.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <string>

#include "ipm_road_mapper/core/io/geojson_export.h"
#include "ipm_road_mapper/core/io/lanelet2_export.h"
#include "ipm_road_mapper/core/map/vector_map.h"

namespace ipm_road_mapper {

// Where the three files of one map go.
struct MapFilePaths {
  std::string json;     // the map (docs/file_formats.md)
  std::string geojson;  // RFC 7946 export (written only with a geo origin)
  std::string tum;      // corrected T_map_base per used frame
  std::string osm;      // Lanelet2 OSM export (written only with a geo origin)
};

// The files of a map saved as `json_path`: "<stem>.json", "<stem>.geojson",
// "<stem>_trajectory_tum.txt" and "<stem>.osm", where <stem> is json_path without a trailing
// ".json". Example: /tmp/m.json -> /tmp/m.geojson, /tmp/m_trajectory_tum.txt, /tmp/m.osm.
MapFilePaths MapFilePathsFor(const std::string& json_path);

// The files of map_from_bag's output folder, by the same rule: map.json, map.geojson,
// map_trajectory_tum.txt.
MapFilePaths MapFilePathsInFolder(const std::string& folder);

// The files of the map made after the `reset`-th ~reset of a live session saving to
// `json_path`: "<stem>_reset<reset>.json" and its siblings (MapFilePathsFor).
MapFilePaths MapFilePathsAfterReset(const std::string& json_path, std::uint64_t reset);

// Why SaveMapFiles wrote no GeoJSON and no Lanelet2 OSM when it had no geo origin.
constexpr const char* kNoGeoJsonNote =
    "no GeoJSON, no Lanelet2 OSM: no geo_origin in the config (local metres are not WGS84)";

// Creates the parent folders and writes the map files: the JSON (with `geo_origin` recorded
// when there is one), the TUM trajectory and, only with a geo origin, the GeoJSON in WGS84
// and the Lanelet2 OSM (lanelet2_export.h). All under temporary names (each fsynced), then
// renamed into place (json, geojson, osm, tum: the TUM file is the last to appear) and the
// folders fsynced. Without an origin a stale `paths.geojson` and `paths.osm` of an earlier
// save are removed, so the folder never holds an export that disagrees with the JSON. When
// any file cannot be written, none of the existing files is replaced. Returns "" when every
// file was written, else one line saying why the exports were not (kNoGeoJsonNote). Throws
// std::runtime_error naming the file and the reason.
std::string SaveMapFiles(const VectorMap& map, const std::optional<GeoOrigin>& geo_origin,
                         const MapFilePaths& paths);

// The files SaveMapFiles writes, comma-separated: the exports only `with_exports` (a geo
// origin).
std::string SavedFilesText(const MapFilePaths& paths, bool with_exports);

// Markings + lanes: what "a map with fewer elements" counts.
std::size_t MapElementCount(const VectorMap& map);

// Which files a live session's saves go to, so that a ~reset never erases a saved map.
// Saves are tagged with the number of resets before their map (its generation). A save of
// generation g > 0 whose map has fewer elements than the last save made is diverted to
// MapFilePathsAfterReset(json_path, g), and every later save of that generation follows
// it there; otherwise (generation 0, or a post-reset map at least as large) the save goes
// to json_path. Not thread-safe: one saver at a time.
class MapSaveTarget {
 public:
  // `json_path`: ros/save_map_path.
  explicit MapSaveTarget(std::string json_path);

  // The files for a map of `elements` elements made after `generation` resets; *diverted
  // is set when they are not json_path's (a post-reset map kept apart).
  MapFilePaths Choose(std::uint64_t generation, std::size_t elements, bool* diverted);

  // Records a successful save of a map of `elements` elements of `generation`.
  void Saved(std::uint64_t generation, std::size_t elements);

  // The configured path (ros/save_map_path).
  const std::string& json_path() const { return json_path_; }

 private:
  const std::string json_path_;
  std::optional<std::size_t> last_saved_elements_;  // of the last save, whatever its files
  std::map<std::uint64_t, bool> diverted_;          // per generation, once its files are chosen
};

}  // namespace ipm_road_mapper
