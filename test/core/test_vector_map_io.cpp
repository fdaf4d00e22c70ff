// Map JSON files: round trips, atomic writes, and the one-line MapFormatError for every
// kind of bad file; the pose JSON and the TUM trajectory. Ground truth: test_ground_truth_io.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <regex>
#include <sstream>
#include <string>

#include "common/file_test_utils.h"
#include "ipm_road_mapper/core/io/ground_truth.h"
#include "ipm_road_mapper/core/map/vector_map.h"

namespace ipm_road_mapper {
namespace {

void ExpectMapsEqual(const VectorMap& a, const VectorMap& b) {
  EXPECT_EQ(a.frame_id, b.frame_id);
  ASSERT_EQ(a.markings.size(), b.markings.size());
  for (std::size_t i = 0; i < a.markings.size(); ++i) {
    EXPECT_EQ(a.markings[i].id, b.markings[i].id);
    EXPECT_EQ(a.markings[i].class_id, b.markings[i].class_id);
    EXPECT_EQ(a.markings[i].class_name, b.markings[i].class_name);
    EXPECT_EQ(a.markings[i].observations, b.markings[i].observations);
    EXPECT_NEAR(a.markings[i].first_seen, b.markings[i].first_seen, 1e-9);
    EXPECT_NEAR(a.markings[i].last_seen, b.markings[i].last_seen, 1e-9);
    EXPECT_EQ(a.markings[i].sides_measured, b.markings[i].sides_measured);
    for (int k = 0; k < 4; ++k) {
      EXPECT_LT((a.markings[i].corners_map[k] - b.markings[i].corners_map[k]).norm(), 1e-9);
    }
  }
  ASSERT_EQ(a.lanes.size(), b.lanes.size());
  for (std::size_t i = 0; i < a.lanes.size(); ++i) {
    EXPECT_EQ(a.lanes[i].id, b.lanes[i].id);
    EXPECT_EQ(a.lanes[i].style, b.lanes[i].style);
    EXPECT_EQ(a.lanes[i].class_name, b.lanes[i].class_name);
    EXPECT_EQ(a.lanes[i].unmeasured, b.lanes[i].unmeasured);
    ASSERT_EQ(a.lanes[i].control_points_map.size(), b.lanes[i].control_points_map.size());
    for (std::size_t k = 0; k < a.lanes[i].control_points_map.size(); ++k) {
      EXPECT_LT((a.lanes[i].control_points_map[k] - b.lanes[i].control_points_map[k]).norm(), 1e-9);
    }
  }
  ExpectPoseNear(a.T_base_cam, b.T_base_cam, 1e-9);
  ExpectPoseNear(a.T_base_cam_initial, b.T_base_cam_initial, 1e-9);
  EXPECT_LT((a.T_base_cam_covariance - b.T_base_cam_covariance).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_EQ(a.T_base_cam_observed, b.T_base_cam_observed);
  ASSERT_EQ(a.trajectory.size(), b.trajectory.size());
  for (std::size_t i = 0; i < a.trajectory.size(); ++i) {
    EXPECT_NEAR(a.trajectory[i].stamp, b.trajectory[i].stamp, 1e-9);
    ExpectPoseNear(a.trajectory[i].T_map_base, b.trajectory[i].T_map_base, 1e-9);
  }
  EXPECT_EQ(a.metadata, b.metadata);
}

// Loading `text` as a map must throw MapFormatError with a one-line message containing
// `expected` (the path it failed at, or the reason).
void ExpectMapRejected(const std::string& path, const std::string& text,
                       const std::string& expected) {
  WriteFile(path, text);
  try {
    LoadVectorMapJson(path);
    ADD_FAILURE() << "accepted: " << text.substr(0, 200);
  } catch (const MapFormatError& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    EXPECT_NE(message.find(expected), std::string::npos) << message;
    EXPECT_EQ(message.rfind(path, 0), 0u) << "should start with the file name: " << message;
  }
}

TEST_F(MapIoTest, MapRoundTripIsExactAndLeavesNoTemporaryFile) {
  const VectorMap map = MakeMap();
  SaveVectorMapJson(map, Path("map.json"));
  ExpectMapsEqual(map, LoadVectorMapJson(Path("map.json")));
  // Overwrite in place: still one file in the folder.
  SaveVectorMapJson(map, Path("map.json"));
  int files = 0;
  for (const auto& entry : fs::directory_iterator(dir_)) {
    ++files;
    EXPECT_EQ(entry.path().filename(), "map.json");
  }
  EXPECT_EQ(files, 1);
  // And through the in-memory JSON conversion.
  ExpectMapsEqual(map, VectorMapFromJson(VectorMapToJson(map)));
}

TEST_F(MapIoTest, MarkingSideFlagsAreWrittenAndOptionalOnRead) {
  const VectorMap map = MakeMap();
  const nlohmann::json j = VectorMapToJson(map);
  EXPECT_EQ(j["markings"][0]["complete"], true);
  EXPECT_EQ(j["markings"][1]["complete"], false);
  EXPECT_EQ(j["markings"][1]["sides_measured"], nlohmann::json({true, false, true, false}));
  // A map written before the flags existed: every marking a whole view.
  nlohmann::json old = j;
  for (auto& m : old["markings"]) {
    m.erase("complete");
    m.erase("sides_measured");
  }
  for (const MapMarking& m : VectorMapFromJson(old).markings) EXPECT_TRUE(m.Complete());
  // `complete` alone sets all four; malformed flags are one-line errors.
  nlohmann::json only_complete = old;
  only_complete["markings"][0]["complete"] = false;
  EXPECT_FALSE(VectorMapFromJson(only_complete).markings[0].Complete());
  nlohmann::json bad = j;
  bad["markings"][0]["sides_measured"] = {true, true, true};
  EXPECT_THROW(VectorMapFromJson(bad), MapFormatError);
  bad["markings"][0]["sides_measured"] = {true, 1, true, true};
  EXPECT_THROW(VectorMapFromJson(bad), MapFormatError);
}

TEST_F(MapIoTest, LaneUnmeasuredRangesAreWrittenCheckedAndOptionalOnRead) {
  const nlohmann::json j = VectorMapToJson(MakeMap());
  EXPECT_EQ(j["lanes"][0]["unmeasured"], nlohmann::json::parse("[[2, 3]]"));
  // A map written before the ranges existed: every control point measured.
  nlohmann::json old = j;
  old["lanes"][0].erase("unmeasured");
  EXPECT_TRUE(VectorMapFromJson(old).lanes[0].unmeasured.empty());
  // Ranges outside the lane's 6 points, reversed, overlapping or malformed are refused.
  for (const char* bad_ranges : {"[[2, 6]]", "[[3, 2]]", "[[1, 3], [3, 4]]", "[[4, 5], [1, 2]]",
                                 "[[1]]", "[[-1, 2]]", "[2, 3]", "{}"}) {
    nlohmann::json bad = j;
    bad["lanes"][0]["unmeasured"] = nlohmann::json::parse(bad_ranges);
    EXPECT_THROW(VectorMapFromJson(bad), MapFormatError) << bad_ranges;
  }
  nlohmann::json two = j;
  two["lanes"][0]["unmeasured"] = nlohmann::json::parse("[[0, 1], [3, 5]]");
  EXPECT_EQ(VectorMapFromJson(two).lanes[0].unmeasured,
            (std::vector<std::pair<std::size_t, std::size_t>>{{0, 1}, {3, 5}}));
}

TEST_F(MapIoTest, SaveRefusesNaNAndKeepsTheOldFile) {
  const VectorMap good = MakeMap();
  SaveVectorMapJson(good, Path("map.json"));
  const std::string before = ReadFile(Path("map.json"));
  VectorMap bad = good;
  bad.lanes[0].control_points_map[2].y() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(SaveVectorMapJson(bad, Path("map.json")), std::runtime_error);
  EXPECT_EQ(ReadFile(Path("map.json")), before);
  EXPECT_THROW(SaveVectorMapJson(good, Path("no_such_folder/map.json")), std::runtime_error);
}

TEST_F(MapIoTest, BadMapFilesThrowOneLineErrors) {
  const std::string path = Path("bad.json");
  const std::string good = VectorMapToJson(MakeMap()).dump(1);
  // Missing file.
  try {
    LoadVectorMapJson(Path("missing.json"));
    ADD_FAILURE() << "missing file accepted";
  } catch (const MapFormatError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot open"), std::string::npos) << e.what();
  }
  ExpectMapRejected(path, "", "not valid JSON");
  ExpectMapRejected(path, "{\"format\": ", "not valid JSON");
  ExpectMapRejected(path, good.substr(0, good.size() / 2), "not valid JSON");  // truncated
  ExpectMapRejected(path, "[1, 2, 3]", "not a JSON object");

  auto mutated = [&](auto&& mutate) {
    nlohmann::json j = VectorMapToJson(MakeMap());
    mutate(j);
    return j.dump();
  };
  ExpectMapRejected(path, mutated([](auto& j) { j["version"] = 2; }), "unsupported version 2");
  ExpectMapRejected(path, mutated([](auto& j) { j["format"] = "other"; }), "format");
  ExpectMapRejected(path, mutated([](auto& j) { j.erase("version"); }), "version: missing");
  ExpectMapRejected(path, mutated([](auto& j) { j["markings"][0]["corners"][1][0] = nullptr; }),
                    "markings[0].corners[1][0]");
  ExpectMapRejected(path, mutated([](auto& j) { j["markings"][1]["corners"].erase(3); }),
                    "expected 4 corners, got 3");
  ExpectMapRejected(path, mutated([](auto& j) {
                      j["lanes"][0]["control_points"][2] = {1.0, 2.0};
                    }),
                    "lanes[0].control_points[2]: expected [x, y, z]");
  ExpectMapRejected(path, mutated([](auto& j) {
                      auto& points = j["lanes"][0]["control_points"];
                      while (points.size() > 3) points.erase(0);
                    }),
                    "at least 4 control points");
  ExpectMapRejected(path, mutated([](auto& j) {
                      j["T_base_cam"]["q_xyzw"] = {0, 0, 0, 2};
                    }),
                    "T_base_cam.q_xyzw");
  ExpectMapRejected(path, mutated([](auto& j) { j["trajectory"][1].erase("stamp"); }),
                    "trajectory[1].stamp");
  ExpectMapRejected(path, mutated([](auto& j) { j["markings"][1]["id"] = 7; }), "duplicate id");
  ExpectMapRejected(path, mutated([](auto& j) { j["lanes"][0]["id"] = -1; }), "lanes[0].id");
  ExpectMapRejected(path, mutated([](auto& j) { j["lanes"][0]["unmeasured"][0][1] = 9; }),
                    "lanes[0].unmeasured[0]: expected first <= last < 6");
  // A bare NaN literal is not JSON at all.
  std::string with_nan = good;
  with_nan.replace(with_nan.find("10.1"), 4, "NaN");
  ExpectMapRejected(path, with_nan, "not valid JSON");
  // The map written before all this still loads: the bad files never replaced it.
  SaveVectorMapJson(MakeMap(), Path("map.json"));
  EXPECT_NO_THROW(LoadVectorMapJson(Path("map.json")));
}

// The optional geo origin: absent by default, written and read back exactly, checked.
TEST_F(MapIoTest, GeoOriginRoundTripAndValidation) {
  VectorMap map = MakeMap();
  EXPECT_FALSE(VectorMapToJson(map).contains("geo_origin"));
  EXPECT_FALSE(VectorMapFromJson(VectorMapToJson(map)).geo_origin);
  map.geo_origin = GeoOrigin{48.137154, 11.576124, 519.25, -37.5};
  SaveVectorMapJson(map, Path("geo.json"));
  const VectorMap loaded = LoadVectorMapJson(Path("geo.json"));
  ASSERT_TRUE(loaded.geo_origin);
  EXPECT_EQ(loaded.geo_origin->latitude_deg, 48.137154);
  EXPECT_EQ(loaded.geo_origin->longitude_deg, 11.576124);
  EXPECT_EQ(loaded.geo_origin->altitude_m, 519.25);
  EXPECT_EQ(loaded.geo_origin->heading_deg, -37.5);  // the heading is recorded too
  nlohmann::json no_altitude = VectorMapToJson(map);
  no_altitude["geo_origin"].erase("altitude_m");
  no_altitude["geo_origin"].erase("heading_deg");  // a map from before the heading: ENU
  EXPECT_EQ(VectorMapFromJson(no_altitude).geo_origin->altitude_m, 0.0);
  EXPECT_EQ(VectorMapFromJson(no_altitude).geo_origin->heading_deg, 0.0);
  nlohmann::json bad_heading = VectorMapToJson(map);
  bad_heading["geo_origin"]["heading_deg"] = 400.0;
  EXPECT_THROW(VectorMapFromJson(bad_heading), MapFormatError);

  const std::string path = Path("bad_geo.json");
  auto mutated = [&](auto&& mutate) {
    nlohmann::json j = VectorMapToJson(map);
    mutate(j);
    return j.dump();
  };
  ExpectMapRejected(path, mutated([](auto& j) { j["geo_origin"]["latitude_deg"] = 91.0; }),
                    "geo_origin.latitude_deg");
  ExpectMapRejected(path, mutated([](auto& j) { j["geo_origin"]["longitude_deg"] = -181.0; }),
                    "geo_origin.longitude_deg");
  ExpectMapRejected(path, mutated([](auto& j) { j["geo_origin"].erase("latitude_deg"); }),
                    "geo_origin.latitude_deg");
  ExpectMapRejected(path, mutated([](auto& j) { j["geo_origin"]["altitude_m"] = "high"; }),
                    "geo_origin.altitude_m");
  ExpectMapRejected(path, mutated([](auto& j) { j["geo_origin"] = 3; }), "geo_origin");
}

TEST_F(MapIoTest, PoseJsonRoundTripAndUnitQuaternion) {
  const Eigen::Isometry3d T = MakePose(1.0, -2.0, 3.0, 0.3, -0.2, 2.9);
  const nlohmann::json j = PoseToJson(T);
  ExpectPoseNear(PoseFromJson(j), T, 1e-12);
  EXPECT_GE(j["q_xyzw"][3].get<double>(), 0.0);  // canonical sign
  EXPECT_THROW(PoseFromJson(nlohmann::json{{"t", {1, 2}}, {"q_xyzw", {0, 0, 0, 1}}}),
               MapFormatError);
}

TEST_F(MapIoTest, TumTrajectoryHasOneLinePerPose) {
  const VectorMap map = MakeMap();
  WriteTumTrajectory(map.trajectory, Path("traj.tum"));
  std::ifstream in(Path("traj.tum"));
  std::string line;
  std::size_t count = 0;
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    double stamp, tx, ty, tz, qx, qy, qz, qw;
    ASSERT_TRUE(fields >> stamp >> tx >> ty >> tz >> qx >> qy >> qz >> qw) << line;
    const StampedPose& pose = map.trajectory[count];
    EXPECT_NEAR(stamp, pose.stamp, 1e-6);
    EXPECT_NEAR(tx, pose.T_map_base.translation().x(), 1e-6);
    const Eigen::Quaterniond q(pose.T_map_base.linear());
    EXPECT_NEAR(std::abs(qz), std::abs(q.z()), 1e-8);
    EXPECT_NEAR(std::sqrt(qx * qx + qy * qy + qz * qz + qw * qw), 1.0, 1e-8);
    ++count;
  }
  EXPECT_EQ(count, map.trajectory.size());
}

}  // namespace
}  // namespace ipm_road_mapper

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
