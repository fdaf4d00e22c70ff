// Ground-truth JSON files: round trip, deterministic bytes, and the errors of bad files.
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
