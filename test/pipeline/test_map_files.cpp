// map_files: one naming rule for the three files, all-or-nothing saves, and the rule that
// keeps a saved map from being overwritten by a smaller one after a ~reset.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <string>

#include "ipm_road_mapper/pipeline/map_files.h"

namespace ipm_road_mapper {
namespace {

namespace fs = std::filesystem;

std::string Read(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::set<std::string> FilesIn(const std::string& dir) {
  std::set<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) names.insert(entry.path().filename());
  return names;
}

// A fresh, empty folder for one test.
std::string TempFolder(const std::string& name) {
  const std::string dir = testing::TempDir() + "/irm_test_map_files/" + name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

VectorMap MapWith(int markings, int lanes) {
  VectorMap map;
  for (int i = 0; i < markings; ++i) {
    MapMarking m;
    m.id = static_cast<std::uint64_t>(i + 1);
    m.class_id = 3;
    m.class_name = "arrow";
    m.corners_map = {Eigen::Vector3d(i, 0, 0), Eigen::Vector3d(i + 1, 0, 0),
                     Eigen::Vector3d(i + 1, 1, 0), Eigen::Vector3d(i, 1, 0)};
    map.markings.push_back(m);
  }
  for (int i = 0; i < lanes; ++i) {
    MapLane lane;
    lane.id = static_cast<std::uint64_t>(100 + i);
    lane.class_id = 1;
    lane.class_name = "lane_solid";
    lane.style = "solid";
    for (int k = 0; k < 4; ++k) lane.control_points_map.emplace_back(k, 3.5 * i, 0);
    map.lanes.push_back(lane);
  }
  StampedPose pose;
  pose.stamp = 1.0;
  map.trajectory.push_back(pose);
  return map;
}

TEST(MapFiles, OneNamingRuleForFilesAndFolders) {
  const MapFilePaths in_folder = MapFilePathsInFolder("/o/run");
  EXPECT_EQ(in_folder.json, "/o/run/map.json");
  EXPECT_EQ(in_folder.geojson, "/o/run/map.geojson");
  EXPECT_EQ(in_folder.tum, "/o/run/map_trajectory_tum.txt");  // as MapFilePathsFor(map.json)
  EXPECT_EQ(in_folder.osm, "/o/run/map.osm");
  EXPECT_EQ(MapFilePathsFor("/o/run/map.json").tum, in_folder.tum);

  const MapFilePaths reset = MapFilePathsAfterReset("/tmp/live.json", 2);
  EXPECT_EQ(reset.json, "/tmp/live_reset2.json");
  EXPECT_EQ(reset.geojson, "/tmp/live_reset2.geojson");
  EXPECT_EQ(reset.tum, "/tmp/live_reset2_trajectory_tum.txt");
  EXPECT_EQ(reset.osm, "/tmp/live_reset2.osm");
  EXPECT_EQ(SavedFilesText(reset, true),
            "/tmp/live_reset2.json, /tmp/live_reset2.geojson, "
            "/tmp/live_reset2.osm, /tmp/live_reset2_trajectory_tum.txt");
  EXPECT_EQ(SavedFilesText(reset, false),
            "/tmp/live_reset2.json, /tmp/live_reset2_trajectory_tum.txt");
  EXPECT_EQ(MapFilePathsAfterReset("/tmp/live", 1).json, "/tmp/live_reset1.json");
}

const GeoOrigin kOrigin{48.0, 11.0, 500.0};

TEST(MapFiles, SaveWritesExactlyTheFourFilesWithAnOrigin) {
  const std::string dir = TempFolder("three");
  const VectorMap map = MapWith(2, 1);
  EXPECT_EQ(SaveMapFiles(map, kOrigin, MapFilePathsFor(dir + "/m.json")), "");
  EXPECT_EQ(SaveMapFiles(map, kOrigin, MapFilePathsFor(dir + "/m.json")), "");  // over them
  EXPECT_EQ(FilesIn(dir), (std::set<std::string>{"m.json", "m.geojson", "m.osm",
                                                 "m_trajectory_tum.txt"}));  // no temporary left
  const VectorMap loaded = LoadVectorMapJson(dir + "/m.json");
  EXPECT_EQ(loaded.markings.size(), 2u);
  EXPECT_EQ(loaded.lanes.size(), 1u);
  ASSERT_TRUE(loaded.geo_origin) << "the origin is recorded in map.json";
  EXPECT_EQ(loaded.geo_origin->latitude_deg, 48.0);
  EXPECT_EQ(loaded.geo_origin->longitude_deg, 11.0);
  EXPECT_EQ(loaded.geo_origin->altitude_m, 500.0);
  EXPECT_NE(Read(dir + "/m.geojson").find("wgs84"), std::string::npos);
  EXPECT_NE(Read(dir + "/m.osm").find("<tag k=\"type\" v=\"line_thin\"/>"), std::string::npos);
  EXPECT_FALSE(Read(dir + "/m_trajectory_tum.txt").empty());
}

// Without an origin the GeoJSON and the OSM would hold local metres read as degrees: none is
// written, the caller is told why, and those left by an earlier save with an origin are removed.
TEST(MapFiles, NoGeoJsonWithoutAnOriginAndAStaleOneIsRemoved) {
  const std::string dir = TempFolder("no_origin");
  const MapFilePaths paths = MapFilePathsFor(dir + "/m.json");
  EXPECT_EQ(SaveMapFiles(MapWith(2, 1), kOrigin, paths), "");
  ASSERT_TRUE(fs::exists(paths.geojson));
  ASSERT_TRUE(fs::exists(paths.osm));
  const std::string note = SaveMapFiles(MapWith(2, 1), std::nullopt, paths);
  EXPECT_EQ(note, kNoGeoJsonNote);
  EXPECT_NE(note.find("geo_origin"), std::string::npos);
  EXPECT_EQ(note.find('\n'), std::string::npos) << "one line";
  EXPECT_EQ(FilesIn(dir), (std::set<std::string>{"m.json", "m_trajectory_tum.txt"}));
  EXPECT_FALSE(LoadVectorMapJson(paths.json).geo_origin);
}

TEST(MapFiles, AFailedSaveReplacesNothingAndNamesTheRealFile) {
  const std::string dir = TempFolder("failed");
  const MapFilePaths paths = MapFilePathsFor(dir + "/m.json");
  SaveMapFiles(MapWith(3, 2), kOrigin, paths);
  const std::string json = Read(paths.json), geojson = Read(paths.geojson), tum = Read(paths.tum),
                    osm = Read(paths.osm);

  VectorMap bad = MapWith(1, 1);  // the map writer refuses what its reader would reject
  bad.markings[0].corners_map[0].x() = std::numeric_limits<double>::quiet_NaN();
  try {
    SaveMapFiles(bad, kOrigin, paths);
    FAIL() << "a map with NaN was saved";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(paths.json), std::string::npos) << what;
    EXPECT_EQ(what.find(".saving."), std::string::npos) << what;
  }
  EXPECT_EQ(Read(paths.json), json);
  EXPECT_EQ(Read(paths.geojson), geojson);
  EXPECT_EQ(Read(paths.tum), tum);
  EXPECT_EQ(Read(paths.osm), osm);
  EXPECT_EQ(FilesIn(dir).size(), 4u);  // the temporaries are gone
}

TEST(MapFiles, AnUnwritableFolderThrowsWithTheFolder) {
  const std::string dir = TempFolder("unwritable");
  std::ofstream(dir + "/file") << "x";  // a file where the folder should be
  try {
    SaveMapFiles(MapWith(1, 0), std::nullopt, MapFilePathsFor(dir + "/file/m.json"));
    FAIL() << "saved below a regular file";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(dir + "/file"), std::string::npos) << e.what();
  }
}

TEST(MapSaveTarget, AResetNeverOverwritesALargerSavedMap) {
  MapSaveTarget target("/tmp/live.json");
  bool diverted = true;
  // Before any reset: always the configured file, even when the map shrinks.
  EXPECT_EQ(target.Choose(0, 10, &diverted).json, "/tmp/live.json");
  EXPECT_FALSE(diverted);
  target.Saved(0, 10);
  EXPECT_EQ(target.Choose(0, 8, &diverted).json, "/tmp/live.json");
  target.Saved(0, 8);
  // After reset 1 the map is smaller: kept apart, and it stays there while it grows.
  EXPECT_EQ(target.Choose(1, 0, &diverted).json, "/tmp/live_reset1.json");
  EXPECT_TRUE(diverted);
  target.Saved(1, 0);
  EXPECT_EQ(target.Choose(1, 50, &diverted).json, "/tmp/live_reset1.json");
  EXPECT_TRUE(diverted);
  target.Saved(1, 50);
  // Reset 2, smaller than the last save (50): its own file.
  EXPECT_EQ(target.Choose(2, 5, &diverted).json, "/tmp/live_reset2.json");
  target.Saved(2, 5);
  // Reset 3 whose first save is at least as large as the last one: the configured file.
  EXPECT_EQ(target.Choose(3, 5, &diverted).json, "/tmp/live.json");
  EXPECT_FALSE(diverted);
}

TEST(MapSaveTarget, TheFirstPostResetSaveDecidesEvenWhenItFailed) {
  MapSaveTarget target("/tmp/live.json");
  bool diverted = false;
  target.Choose(0, 4, &diverted);
  target.Saved(0, 4);
  EXPECT_TRUE((target.Choose(1, 1, &diverted), diverted));  // say this save failed
  EXPECT_EQ(target.Choose(1, 9, &diverted).json, "/tmp/live_reset1.json");
}

}  // namespace
}  // namespace ipm_road_mapper
