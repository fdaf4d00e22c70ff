#include "ipm_road_mapper/pipeline/map_files.h"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <set>
#include <stdexcept>
#include <utility>
#include <vector>

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

// A name in the folder of `path` that no other save (thread or process) uses at once.
std::string TemporarySibling(const std::string& path) {
  static std::atomic<std::uint64_t> counter{0};
  const fs::path p(path);
  const std::string name = "." + p.filename().string() + ".saving." + std::to_string(::getpid()) +
                           "." + std::to_string(++counter);
  return (p.parent_path() / name).string();
}

// fsync of a folder, so that a rename in it survives a power loss (best effort: some file
// systems refuse to open folders for reading).
void SyncFolder(const std::string& path) {
  std::string folder = fs::path(path).parent_path().string();
  if (folder.empty()) folder = ".";
  const int fd = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}

}  // namespace

MapFilePaths MapFilePathsFor(const std::string& json_path) {
  const std::string suffix = ".json";
  std::string stem = json_path;
  if (stem.size() > suffix.size() &&
      stem.compare(stem.size() - suffix.size(), suffix.size(), suffix) == 0) {
    stem.resize(stem.size() - suffix.size());
  }
  return {stem + ".json", stem + ".geojson", stem + "_trajectory_tum.txt", stem + ".osm"};
}

MapFilePaths MapFilePathsInFolder(const std::string& folder) {
  return MapFilePathsFor((fs::path(folder) / "map.json").string());
}

MapFilePaths MapFilePathsAfterReset(const std::string& json_path, std::uint64_t reset) {
  const MapFilePaths base = MapFilePathsFor(json_path);
  const std::string stem = base.json.substr(0, base.json.size() - 5);  // without ".json"
  return MapFilePathsFor(stem + "_reset" + std::to_string(reset) + ".json");
}

std::string SaveMapFiles(const VectorMap& map, const std::optional<GeoOrigin>& geo_origin,
                         const MapFilePaths& paths) {
  for (const std::string* path : {&paths.json, &paths.geojson, &paths.tum, &paths.osm}) {
    CreateParent(*path);
  }
  std::vector<std::pair<std::string, std::string>> moves = {
      {TemporarySibling(paths.json), paths.json}};  // temporary -> final, in rename order
  if (geo_origin) {
    moves.emplace_back(TemporarySibling(paths.geojson), paths.geojson);
    moves.emplace_back(TemporarySibling(paths.osm), paths.osm);
  }
  moves.emplace_back(TemporarySibling(paths.tum), paths.tum);
  auto remove_temporaries = [&] {
    for (const auto& move : moves) std::remove(move.first.c_str());
  };
  // Each core writer is atomic and fsyncs its file; here under the temporary names.
  try {
    VectorMap recorded = map;  // the JSON records the origin the GeoJSON was made with
    recorded.geo_origin = geo_origin;
    SaveVectorMapJson(recorded, moves.front().first);
    if (geo_origin) {
      SaveGeoJson(map, geo_origin, moves[1].first);
      SaveLanelet2Osm(map, *geo_origin, moves[2].first);
    }
    WriteTumTrajectory(map.trajectory, moves.back().first);
  } catch (const std::exception& e) {
    remove_temporaries();
    // The core names the temporary file; the caller asked for the real one.
    std::string what = e.what();
    for (const auto& [from, to] : moves) {
      for (std::size_t at = what.find(from); at != std::string::npos; at = what.find(from)) {
        what.replace(at, from.size(), to);
      }
    }
    throw std::runtime_error(what);
  }
  for (const auto& [from, to] : moves) {
    if (std::rename(from.c_str(), to.c_str()) != 0) {
      const std::string reason = std::strerror(errno);
      remove_temporaries();
      throw std::runtime_error(to + ": cannot rename the temporary file into place: " + reason);
    }
  }
  std::error_code ignored;  // a stale export that cannot be removed is left, not fatal
  if (!geo_origin) {
    fs::remove(paths.geojson, ignored);
    fs::remove(paths.osm, ignored);
  }
  std::set<std::string> folders;
  for (const auto& move : moves) folders.insert(fs::path(move.second).parent_path().string());
  for (const std::string& folder : folders) SyncFolder((fs::path(folder) / "x").string());
  return geo_origin ? "" : kNoGeoJsonNote;
}

std::string SavedFilesText(const MapFilePaths& paths, bool with_exports) {
  return paths.json + ", " + (with_exports ? paths.geojson + ", " + paths.osm + ", " : "") +
         paths.tum;
}

std::size_t MapElementCount(const VectorMap& map) { return map.markings.size() + map.lanes.size(); }

MapSaveTarget::MapSaveTarget(std::string json_path) : json_path_(std::move(json_path)) {}

MapFilePaths MapSaveTarget::Choose(std::uint64_t generation, std::size_t elements, bool* diverted) {
  auto known = diverted_.find(generation);
  if (known == diverted_.end()) {
    const bool fewer = last_saved_elements_ && elements < *last_saved_elements_;
    known = diverted_.emplace(generation, generation > 0 && fewer).first;
  }
  *diverted = known->second;
  return known->second ? MapFilePathsAfterReset(json_path_, generation)
                       : MapFilePathsFor(json_path_);
}

void MapSaveTarget::Saved(std::uint64_t generation, std::size_t elements) {
  diverted_.emplace(generation, false);  // chosen already when Choose was called
  last_saved_elements_ = elements;
}

}  // namespace ipm_road_mapper
