#include "ipm_road_mapper/pipeline/map_files.h"

#include <filesystem>
#include <stdexcept>

namespace ipm_road_mapper {
namespace {

namespace fs = std::filesystem;

void CreateParent(const std::string& path) {
  const fs::path parent = fs::path(path).parent_path();
  if (parent.empty()) return;
  std::error_code error;
  fs::create_directories(parent, error);
  if (error || !fs::is_directory(parent)) {
    throw std::runtime_error(parent.string() + ": cannot create folder: " + error.message());
  }
}

}  // namespace

MapFilePaths MapFilePathsFor(const std::string& json_path) {
  const std::string suffix = ".json";
  std::string stem = json_path;
  if (stem.size() > suffix.size() &&
      stem.compare(stem.size() - suffix.size(), suffix.size(), suffix) == 0) {
    stem.resize(stem.size() - suffix.size());
  }
  return {stem + ".json", stem + ".geojson", stem + "_trajectory_tum.txt"};
}

MapFilePaths MapFilePathsInFolder(const std::string& folder) {
  const fs::path dir(folder);
  return {(dir / "map.json").string(), (dir / "map.geojson").string(),
          (dir / "trajectory_tum.txt").string()};
}

void SaveMapFiles(const VectorMap& map, const std::optional<GeoOrigin>& geo_origin,
                  const MapFilePaths& paths) {
  for (const std::string* path : {&paths.json, &paths.geojson, &paths.tum}) CreateParent(*path);
  SaveVectorMapJson(map, paths.json);
  SaveGeoJson(map, geo_origin, paths.geojson);
  WriteTumTrajectory(map.trajectory, paths.tum);
}

}  // namespace ipm_road_mapper
