// The shared config loader (the ros: section is typed and validated like the core's),
// the map file names of ~save_map, and the extrinsic choice (config first, then tf).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "ipm_road_mapper/pipeline/extrinsic_source.h"
#include "ipm_road_mapper/pipeline/map_files.h"
#include "ipm_road_mapper/pipeline/mapper_config.h"

namespace ipm_road_mapper {
namespace {

MapperConfig Load(const std::string& yaml) {
  return LoadMapperConfig(OptionsReader(YAML::Load(yaml), ""));
}

std::string ErrorOf(const std::string& yaml) {
  try {
    Load(yaml);
  } catch (const OptionsError& e) {
    return e.what();
  }
  return "";
}

TEST(MapperConfig, PackageConfigsLoadAndRosYamlStatesTheDefaults) {
  const std::string dir = std::string(IRM_SOURCE_DIR) + "/config/";
  const MapperConfig config = LoadMapperConfigFile(dir + "mapper.yaml");
  EXPECT_EQ(config.ros.sync, "exact");
  EXPECT_FALSE(config.geo_origin.has_value());
  // The ablation configs overlay it (base:) and load as well.
  EXPECT_NO_THROW(LoadMapperConfigFile(dir + "ablations/ipm.yaml"));
  // config/ros.yaml (loaded by mapper.launch) holds exactly the struct's defaults.
  const RosOptions defaults;
  const RosOptions file = LoadRosOptions(OptionsReader::FromFile(dir + "ros.yaml").Child("ros"));
  EXPECT_EQ(ToString(file), ToString(defaults));
  EXPECT_DOUBLE_EQ(file.publish_rate_hz, 2.0);
  EXPECT_EQ(file.sync_queue_size, 10);
  // Both in one tree load too (what the nodelet's private namespace holds).
  YAML::Node both = YAML::LoadFile(dir + "mapper.yaml");
  both["ros"] = YAML::LoadFile(dir + "ros.yaml")["ros"];
  EXPECT_DOUBLE_EQ(LoadMapperConfig(OptionsReader(both, "")).ros.debug_image_rate_hz, 5.0);
}

TEST(MapperConfig, RosSectionIsTypedAndValidated) {
  const MapperConfig config = Load(
      "ros: {publish_rate_hz: 5.0, refined_camera_frame: cam_refined, save_map_path: /tmp/m.json}\n"
      "geo_origin: {latitude_deg: 48.0, longitude_deg: 11.0}");
  EXPECT_DOUBLE_EQ(config.ros.publish_rate_hz, 5.0);
  EXPECT_EQ(config.ros.refined_camera_frame, "cam_refined");
  EXPECT_EQ(config.ros.save_map_path, "/tmp/m.json");
  ASSERT_TRUE(config.geo_origin.has_value());
  EXPECT_NE(ErrorOf("ros: {publish_rat_hz: 5.0}").find("ros.publish_rat_hz"), std::string::npos);
  EXPECT_NE(ErrorOf("ros: {publish_rate_hz: -1}").find("ros.publish_rate_hz"), std::string::npos);
  EXPECT_NE(ErrorOf("ros: {sync_queue_size: 0}").find("ros.sync_queue_size"), std::string::npos);
  EXPECT_NE(ErrorOf("ros: {map_frame: /map}").find("ros.map_frame"), std::string::npos);
  // REP-105 frames: both named, distinct (map -> odom is broadcast between them).
  EXPECT_NE(ErrorOf("ros: {map_frame: ''}").find("ros.map_frame"), std::string::npos);
  EXPECT_NE(ErrorOf("ros: {odom_frame: map}").find("ros.odom_frame"), std::string::npos);
  EXPECT_NE(ErrorOf("ros: {publish_map_to_odom: 3}").find("ros.publish_map_to_odom"),
            std::string::npos);
  EXPECT_EQ(Load("ros: {sync: exact}").ros.map_frame, "map");
  EXPECT_EQ(Load("ros: {sync: exact}").ros.odom_frame, "odom");
  EXPECT_TRUE(Load("ros: {sync: exact}").ros.publish_map_to_odom);
  EXPECT_NE(ErrorOf("ros: {odometry_wait_s: abc}").find("wrong type"), std::string::npos);
  EXPECT_NE(ErrorOf("bogus: 1").find("bogus"), std::string::npos);  // core keys still checked
  EXPECT_NE(ErrorOf("ipm: {max_range_m: -3}").find("ipm.max_range_m"), std::string::npos);
  EXPECT_FALSE(ToString(config.ros).empty());
}

TEST(MapperConfig, TopicsAndSyncAreRosOptions) {
  const MapperConfig config = Load(
      "ros: {mask_topic: /m, camera_info_topic: /ci, image_topic: '', odom_topic: /o, "
      "sync: approximate}");
  EXPECT_EQ(config.ros.mask_topic, "/m");
  EXPECT_EQ(config.ros.camera_info_topic, "/ci");
  EXPECT_EQ(config.ros.image_topic, "");
  EXPECT_EQ(config.ros.odom_topic, "/o");
  EXPECT_EQ(config.ros.sync, "approximate");
  EXPECT_NE(ErrorOf("ros: {sync: sometimes}").find("ros.sync"), std::string::npos);
  EXPECT_NE(ErrorOf("ros: {mask_topic: ''}").find("ros.mask_topic"), std::string::npos);
  // They left the core's input section: an old config says where they went (unknown key).
  EXPECT_NE(ErrorOf("input: {mask_topic: /m}").find("input.mask_topic"), std::string::npos);
  EXPECT_NE(ErrorOf("input: {sync: exact}").find("input.sync"), std::string::npos);
}

TEST(MapperConfig, AutosavePeriodIsValidated) {
  EXPECT_DOUBLE_EQ(RosOptions().autosave_period_s, 30.0);
  EXPECT_DOUBLE_EQ(Load("ros: {autosave_period_s: 2.5}").ros.autosave_period_s, 2.5);
  EXPECT_DOUBLE_EQ(Load("ros: {autosave_period_s: 0}").ros.autosave_period_s, 0.0);  // off
  EXPECT_NE(ErrorOf("ros: {autosave_period_s: -1}").find("ros.autosave_period_s"),
            std::string::npos);
  EXPECT_NE(ErrorOf("ros: {autosave_period_s: .nan}").find("ros.autosave_period_s"),
            std::string::npos);
  EXPECT_NE(ToString(RosOptions()).find("ros.autosave_period_s: 30"), std::string::npos);
}

TEST(MapperConfig, ThreadingOptionsAreValidated) {
  const RosOptions defaults;
  EXPECT_DOUBLE_EQ(defaults.shutdown_budget_s, 3.0);
  EXPECT_DOUBLE_EQ(Load("ros: {shutdown_budget_s: 0.5}").ros.shutdown_budget_s, 0.5);
  EXPECT_NE(ErrorOf("ros: {shutdown_budget_s: 0}").find("ros.shutdown_budget_s"),
            std::string::npos);
  EXPECT_NE(ErrorOf("ros: {shutdown_budget_s: -1}").find("ros.shutdown_budget_s"),
            std::string::npos);
  EXPECT_NE(ErrorOf("ros: {input_queue_size: 0}").find("ros.input_queue_size"), std::string::npos);
  EXPECT_NE(ErrorOf("ros: {marker_full_period_s: 0}").find("ros.marker_full_period_s"),
            std::string::npos);
}

TEST(MapperConfig, LiveNodeletRefusesASynchronousBackend) {
  EXPECT_EQ(CheckLiveConfig(Load("")), "");
  const std::string error = CheckLiveConfig(Load("backend: {synchronous: true}"));
  EXPECT_NE(error.find("backend.synchronous"), std::string::npos);
  EXPECT_NE(error.find("stall"), std::string::npos);
  // The package's config runs live.
  EXPECT_EQ(
      CheckLiveConfig(LoadMapperConfigFile(std::string(IRM_SOURCE_DIR) + "/config/mapper.yaml")),
      "");
}

TEST(MapFiles, NamesAndWriting) {
  const MapFilePaths a = MapFilePathsFor("/tmp/x/live.json");
  EXPECT_EQ(a.json, "/tmp/x/live.json");
  EXPECT_EQ(a.geojson, "/tmp/x/live.geojson");
  EXPECT_EQ(a.tum, "/tmp/x/live_trajectory_tum.txt");
  const MapFilePaths b = MapFilePathsFor("/tmp/x/live");
  EXPECT_EQ(b.json, "/tmp/x/live.json");
  EXPECT_EQ(MapFilePathsInFolder("/o").geojson, "/o/map.geojson");

  const std::string dir = testing::TempDir() + "/irm_map_files_test/sub";
  std::filesystem::remove_all(dir);
  VectorMap map;
  StampedPose pose;
  pose.stamp = 1.0;
  map.trajectory.push_back(pose);
  SaveMapFiles(map, GeoOrigin{48.0, 11.0, 0.0}, MapFilePathsFor(dir + "/m.json"));  // mkdir
  EXPECT_NO_THROW(LoadVectorMapJson(dir + "/m.json"));
  EXPECT_TRUE(std::filesystem::exists(dir + "/m.geojson"));
  std::ifstream tum(dir + "/m_trajectory_tum.txt");
  std::string line;
  EXPECT_TRUE(static_cast<bool>(std::getline(tum, line)));
  EXPECT_THROW(SaveMapFiles(map, std::nullopt, MapFilePathsFor("/proc/nope/m.json")),
               std::runtime_error);
}

TEST(ExtrinsicSource, ConfigFirstThenLookup) {
  InputOptions input;
  Eigen::Isometry3d T_tf = Eigen::Isometry3d::Identity();
  T_tf.translation() = Eigen::Vector3d(1, 2, 3);
  int lookups = 0;
  const TransformLookup lookup = [&](const std::string& parent, const std::string& child,
                                     Eigen::Isometry3d* T) -> std::string {
    ++lookups;
    if (parent != "base_link" || child != "cam") return parent + " -> " + child + " unknown";
    *T = T_tf;
    return "";
  };
  ExtrinsicChoice choice;
  EXPECT_EQ(ChooseExtrinsic(input, "cam", lookup, "tf", &choice), "");
  EXPECT_EQ(choice.source, "tf base_link -> cam");
  EXPECT_TRUE(choice.T_base_cam.isApprox(T_tf));
  EXPECT_NE(ChooseExtrinsic(input, "other", lookup, "tf", &choice).find("no extrinsic"),
            std::string::npos);
  EXPECT_NE(ChooseExtrinsic(input, "", lookup, "tf", &choice).find("header.frame_id"),
            std::string::npos);
  T_tf.matrix()(0, 0) = std::nan("");
  EXPECT_NE(ChooseExtrinsic(input, "cam", lookup, "tf", &choice).find("not a finite"),
            std::string::npos);

  input.T_base_cam = Eigen::Isometry3d::Identity();
  const int before = lookups;
  EXPECT_EQ(ChooseExtrinsic(input, "", lookup, "tf", &choice), "");
  EXPECT_EQ(choice.source, "config input.extrinsic");
  EXPECT_EQ(lookups, before);  // the config wins without asking tf
}

}  // namespace
}  // namespace ipm_road_mapper
