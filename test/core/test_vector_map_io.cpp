// Map and ground-truth JSON files: round trips, atomic writes, deterministic bytes, and the
// one-line MapFormatError for every kind of bad file.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <regex>
#include <sstream>
#include <string>

#include "ipm_road_mapper/core/io/ground_truth.h"
#include "ipm_road_mapper/core/map/vector_map.h"

namespace ipm_road_mapper {
namespace {

namespace fs = std::filesystem;

// A fresh temporary folder per test, removed afterwards.
class MapIoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    char pattern[] = "/tmp/irm_map_io_XXXXXX";
    ASSERT_NE(mkdtemp(pattern), nullptr);
    dir_ = pattern;
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string Path(const std::string& name) const { return dir_ + "/" + name; }

  std::string dir_;
};

Eigen::Isometry3d MakePose(double x, double y, double z, double roll, double pitch, double yaw) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = RotationFromRpy(roll, pitch, yaw);
  T.translation() = Eigen::Vector3d(x, y, z);
  return T;
}

VectorMap MakeMap() {
  VectorMap map;
  MapMarking marking;
  marking.id = 7;
  marking.class_id = 10;
  marking.class_name = "arrow_straight";
  marking.corners_map = {Eigen::Vector3d(10.1, -1.2, 0.013), Eigen::Vector3d(10.1, -0.6, 0.014),
                         Eigen::Vector3d(14.9, -0.6, 0.021), Eigen::Vector3d(14.9, -1.2, 0.02)};
  marking.observations = 12;
  marking.first_seen = 1700000000.05;
  marking.last_seen = 1700000001.55;
  map.markings.push_back(marking);
  marking.id = 18446744073709551615ULL;                 // the largest id must survive too
  marking.sides_measured = {true, false, true, false};  // a crossing wider than the view
  map.markings.push_back(marking);
  MapLane lane;
  lane.id = 3;
  lane.class_id = 2;
  lane.class_name = "lane_white_dashed";
  lane.style = "dashed";
  for (int k = 0; k < 6; ++k) {
    lane.control_points_map.emplace_back(3.0 * k - 3.0, 1.75 + 0.01 * k * k, 0.001 * k);
  }
  lane.observations = 40;
  map.lanes.push_back(lane);
  map.T_base_cam = MakePose(1.5, 0.02, 1.4, -M_PI / 2 - 0.01, 0.003, -M_PI / 2 + 0.02);
  map.T_base_cam_initial = MakePose(1.5, 0.0, 1.45, -M_PI / 2, 0.0, -M_PI / 2);
  for (int i = 0; i < 6; ++i) {
    for (int k = 0; k < 6; ++k)
      map.T_base_cam_covariance(i, k) = (i == k ? 1e-4 : 1e-6) * (1 + i + 7 * k);
  }
  map.T_base_cam_observed = {true, true, false, false, true, true};
  for (int k = 0; k < 3; ++k) {
    map.trajectory.push_back({1700000000.0 + 0.05 * k, MakePose(k, 0.1 * k, 0.0, 0, 0, 0.01 * k)});
  }
  map.metadata = {{"method", "Ours(+PPSR)"}, {"frames", 3}};
  return map;
}

void ExpectPoseNear(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b, double tolerance) {
  EXPECT_LT((a.matrix() - b.matrix()).cwiseAbs().maxCoeff(), tolerance);
}

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

std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void WriteFile(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
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

GroundTruth MakeGroundTruth() {
  GroundTruth gt;
  gt.scenario = "straight_2lanes";
  gt.seed = 4000000000u;
  gt.frame_rate_hz = 20.0;
  gt.camera.width = 1280;
  gt.camera.height = 720;
  gt.camera.fx = gt.camera.fy = 1000.0;
  gt.camera.cx = 640.0;
  gt.camera.cy = 360.0;
  gt.camera.distortion = {-0.1, 0.01, 0.0, 0.0, 1e-7};
  gt.T_base_cam_true = MakePose(1.5, 0.0, 1.4, -M_PI / 2 - 0.05, 0.0, -M_PI / 2);
  gt.T_base_cam_rough = MakePose(1.5, 0.0, 1.45, -M_PI / 2, 0.0, -M_PI / 2);
  GroundTruthMarking marking;
  marking.id = 1;
  marking.class_id = 10;
  marking.class_name = "arrow_straight";
  marking.corners_map = {Eigen::Vector3d(10, -1, 0.01), Eigen::Vector3d(10, -0.5, 0.01),
                         Eigen::Vector3d(15, -0.5, 0.02), Eigen::Vector3d(15, -1, 0.02)};
  marking.center_map = Eigen::Vector3d(12.5, -0.75, 0.015);
  marking.visible_frames = 31;
  gt.markings.push_back(marking);
  GroundTruthLane lane;
  lane.id = 2;
  lane.class_id = 1;
  lane.class_name = "lane_white_solid";
  lane.style = "solid";
  for (int k = 0; k <= 100; ++k) lane.points_map.emplace_back(0.1 * k, 1.75, 1e-4 * k / 3.0);
  gt.lanes.push_back(lane);
  for (int k = 0; k < 5; ++k) {
    GroundTruthFrame frame;
    frame.stamp = 1700000000.0 + k / 20.0;
    frame.T_map_base_true = MakePose(0.5 * k, 0.0, 0.0, 0.0, 0.001 * k, 0.0);
    frame.T_map_base_odom = MakePose(0.5 * k + 0.1 / 3.0, 0.02, 0.0, 0.0, 0.0, 0.003 * k);
    gt.frames.push_back(frame);
  }
  return gt;
}

TEST_F(MapIoTest, GroundTruthRoundTripAndDeterministicBytes) {
  const GroundTruth gt = MakeGroundTruth();
  SaveGroundTruthJson(gt, Path("gt1.json"));
  SaveGroundTruthJson(gt, Path("gt2.json"));
  const std::string bytes = ReadFile(Path("gt1.json"));
  EXPECT_EQ(bytes, ReadFile(Path("gt2.json")));
  // Rounded numbers print short (1.55, never 1.5499999999999998): at most 9 decimals.
  std::smatch long_number;
  EXPECT_FALSE(std::regex_search(bytes, long_number, std::regex(R"([0-9]\.[0-9]{10,})")))
      << long_number.str();

  const GroundTruth loaded = LoadGroundTruthJson(Path("gt1.json"));
  EXPECT_EQ(loaded.scenario, gt.scenario);
  EXPECT_EQ(loaded.seed, gt.seed);
  EXPECT_EQ(loaded.frame_rate_hz, gt.frame_rate_hz);
  EXPECT_EQ(loaded.camera.width, gt.camera.width);
  EXPECT_EQ(loaded.camera.distortion, gt.camera.distortion);
  ExpectPoseNear(loaded.T_base_cam_true, gt.T_base_cam_true, 1e-6);
  ExpectPoseNear(loaded.T_base_cam_rough, gt.T_base_cam_rough, 1e-6);
  ASSERT_EQ(loaded.markings.size(), 1u);
  EXPECT_EQ(loaded.markings[0].visible_frames, 31);
  EXPECT_EQ(loaded.markings[0].class_name, "arrow_straight");
  EXPECT_LT((loaded.markings[0].center_map - gt.markings[0].center_map).norm(), 1e-6);
  for (int k = 0; k < 4; ++k) {
    EXPECT_LT((loaded.markings[0].corners_map[k] - gt.markings[0].corners_map[k]).norm(), 1e-6);
  }
  ASSERT_EQ(loaded.lanes.size(), 1u);
  ASSERT_EQ(loaded.lanes[0].points_map.size(), gt.lanes[0].points_map.size());
  for (std::size_t k = 0; k < gt.lanes[0].points_map.size(); ++k) {
    EXPECT_LT((loaded.lanes[0].points_map[k] - gt.lanes[0].points_map[k]).norm(), 1e-6);
  }
  ASSERT_EQ(loaded.frames.size(), gt.frames.size());
  for (std::size_t k = 0; k < gt.frames.size(); ++k) {
    EXPECT_NEAR(loaded.frames[k].stamp, gt.frames[k].stamp, 1e-9);
    ExpectPoseNear(loaded.frames[k].T_map_base_true, gt.frames[k].T_map_base_true, 1e-6);
    ExpectPoseNear(loaded.frames[k].T_map_base_odom, gt.frames[k].T_map_base_odom, 1e-6);
  }
  // Saving what was loaded gives the same bytes again (rounding is idempotent).
  SaveGroundTruthJson(loaded, Path("gt3.json"));
  EXPECT_EQ(bytes, ReadFile(Path("gt3.json")));
}

TEST_F(MapIoTest, BadGroundTruthFilesThrow) {
  GroundTruth gt = MakeGroundTruth();
  SaveGroundTruthJson(gt, Path("gt.json"));
  const std::string good = ReadFile(Path("gt.json"));
  WriteFile(Path("truncated.json"), good.substr(0, good.size() - 20));
  EXPECT_THROW(LoadGroundTruthJson(Path("truncated.json")), MapFormatError);
  EXPECT_THROW(LoadGroundTruthJson(Path("missing.json")), MapFormatError);
  nlohmann::json j = nlohmann::json::parse(good);
  j["markings"][0].erase("visible_frames");
  WriteFile(Path("no_visibility.json"), j.dump());
  EXPECT_THROW(LoadGroundTruthJson(Path("no_visibility.json")), MapFormatError);
  // A map is not a ground truth.
  SaveVectorMapJson(MakeMap(), Path("map.json"));
  EXPECT_THROW(LoadGroundTruthJson(Path("map.json")), MapFormatError);
  gt.lanes[0].points_map[3].z() = std::numeric_limits<double>::infinity();
  EXPECT_THROW(SaveGroundTruthJson(gt, Path("gt_inf.json")), std::runtime_error);
}

}  // namespace
}  // namespace ipm_road_mapper

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
