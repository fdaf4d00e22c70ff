// The calibration file (map_from_bag --calibration-out): it round-trips into input.extrinsic,
// alone and as a complete config over a base, and its static_transform_publisher line and
// URDF joint state the same transform.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "ipm_road_mapper/core/geometry/rigid_transform.h"
#include "ipm_road_mapper/pipeline/extrinsic_source.h"
#include "ipm_road_mapper/pipeline/mapper_config.h"

namespace ipm_road_mapper {
namespace {

// A refined extrinsic: 1.62 m ahead, 0.01 m left, 1.71 m up, looking ahead and a little down.
Calibration MakeCalibration() {
  Calibration c;
  c.T_base_cam.linear() =
      RotationFromRpy(-90.3 * M_PI / 180.0, 0.37 * M_PI / 180.0, -89.6 * M_PI / 180.0);
  c.T_base_cam.translation() = Eigen::Vector3d(1.62, 0.01, 1.71);
  c.covariance = Eigen::Matrix<double, 6, 6>::Identity() * 1e-6;
  c.covariance(3, 3) = c.covariance(4, 4) = 0.05 * 0.05;
  c.observed = {true, true, true, false, false, true};
  c.camera_frame = "camera_optical";
  c.note = "from a test";
  return c;
}

void ExpectSameTransform(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  EXPECT_LT(RotationAngleBetween(a, b), 1e-8);
  EXPECT_LT((a.translation() - b.translation()).norm(), 1e-8);
}

TEST(CalibrationFile, RoundTripsIntoInputExtrinsic) {
  const Calibration c = MakeCalibration();
  const std::string text = CalibrationYaml(c, "");
  const MapperConfig config = LoadMapperConfig(OptionsReader(YAML::Load(text), ""));
  ASSERT_TRUE(config.mapper.input.T_base_cam.has_value()) << text;
  ExpectSameTransform(*config.mapper.input.T_base_cam, c.T_base_cam);
  // Where it came from, what was observed, the sigmas (x, y: 5 cm) are in the comments.
  EXPECT_NE(text.find("# from a test"), std::string::npos) << text;
  EXPECT_NE(text.find("observed by the data: roll pitch yaw z"), std::string::npos) << text;
  EXPECT_NE(text.find("x y z 0.05 0.05 0.001 m"), std::string::npos) << text;
  // And ChooseExtrinsic takes it over any tf.
  ExtrinsicChoice choice;
  EXPECT_EQ(ChooseExtrinsic(config.mapper.input, "camera_optical", nullptr, "tf", &choice), "");
  EXPECT_EQ(choice.source, "config input.extrinsic");
  ExpectSameTransform(choice.T_base_cam, c.T_base_cam);
}

TEST(CalibrationFile, IsACompleteConfigOverItsBase) {
  const std::string dir = testing::TempDir() + "/calibration_file_test";
  std::filesystem::create_directories(dir);
  const std::string path = dir + "/calibration.yaml";
  const Calibration c = MakeCalibration();
  ASSERT_EQ(WriteCalibrationFile(path, c, std::string(IRM_SOURCE_DIR) + "/config/mapper.yaml"), "");
  const MapperConfig config = LoadMapperConfigFile(path);
  ASSERT_TRUE(config.mapper.input.T_base_cam.has_value());
  ExpectSameTransform(*config.mapper.input.T_base_cam, c.T_base_cam);
  // The rest is the base's.
  const MapperConfig base =
      LoadMapperConfigFile(std::string(IRM_SOURCE_DIR) + "/config/mapper.yaml");
  EXPECT_EQ(config.mapper.backend.window_frames, base.mapper.backend.window_frames);
  EXPECT_EQ(config.ros.sync, base.ros.sync);
  EXPECT_NE(WriteCalibrationFile(dir + "/no/such/folder/c.yaml", c, ""), "");
}

TEST(CalibrationFile, StaticTransformPublisherAndUrdfStateTheSameTransform) {
  const Calibration c = MakeCalibration();
  const std::string text = CalibrationYaml(c, "");
  const std::string key = "static_transform_publisher ";
  const std::size_t at = text.find(key);
  ASSERT_NE(at, std::string::npos) << text;
  std::istringstream line(text.substr(at + key.size()));
  double x, y, z, qx, qy, qz, qw;
  std::string parent, child;
  line >> x >> y >> z >> qx >> qy >> qz >> qw >> parent >> child;
  EXPECT_EQ(parent, "base_link");
  EXPECT_EQ(child, "camera_optical");
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Quaterniond(qw, qx, qy, qz).normalized().toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, y, z);
  ExpectSameTransform(T, c.T_base_cam);
  // URDF: origin xyz and rpy (fixed axes: R = Rz(yaw) Ry(pitch) Rx(roll)).
  const std::size_t origin = text.find("<origin xyz=\"");
  ASSERT_NE(origin, std::string::npos);
  std::string rest = text.substr(origin + 13);
  for (char& ch : rest) {
    if (ch == '"') ch = ' ';
  }
  std::istringstream urdf(rest);
  std::string rpy_key;
  double r, p, yaw;
  urdf >> x >> y >> z >> rpy_key >> r >> p >> yaw;
  EXPECT_EQ(rpy_key, "rpy=");
  T.linear() = RotationFromRpy(r, p, yaw);
  T.translation() = Eigen::Vector3d(x, y, z);
  ExpectSameTransform(T, c.T_base_cam);
}

}  // namespace
}  // namespace ipm_road_mapper
