// Helpers the file tests share (test_vector_map_io, test_ground_truth_io): a fixture with a
// fresh temporary folder per test, a pose from x y z roll pitch yaw, a pose comparison, and
// reading / writing a whole file, and a small map with every field.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "ipm_road_mapper/core/geometry/rigid_transform.h"
#include "ipm_road_mapper/core/map/vector_map.h"

namespace ipm_road_mapper {

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

inline Eigen::Isometry3d MakePose(double x, double y, double z, double roll, double pitch,
                                  double yaw) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = RotationFromRpy(roll, pitch, yaw);
  T.translation() = Eigen::Vector3d(x, y, z);
  return T;
}

inline void ExpectPoseNear(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b,
                           double tolerance) {
  EXPECT_LT((a.matrix() - b.matrix()).cwiseAbs().maxCoeff(), tolerance);
}

inline std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

inline void WriteFile(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

// A small map with every field set (markings, lanes, extrinsic, trajectory, metadata).
inline VectorMap MakeMap() {
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
  lane.unmeasured = {{2, 3}};  // laid by a join across a gap in its observations
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

}  // namespace ipm_road_mapper
