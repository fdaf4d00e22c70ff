// The pose error over the frames where the vehicle moves, and the true extrinsic in config
// form, on a small drive built here: 20 frames standing, then 40 frames at 10 m/s.
#include <gtest/gtest.h>

#include <cmath>

#include "ipm_road_mapper/eval/evaluation.h"

namespace ipm_road_mapper {
namespace {

constexpr double kDegToRad = M_PI / 180.0;
constexpr int kStanding = 20;
constexpr int kMoving = 40;

GroundTruth StandThenDrive() {
  GroundTruth gt;
  gt.T_base_cam_true.linear() =
      RotationFromRpy(-91.0 * kDegToRad, 2.0 * kDegToRad, -89.5 * kDegToRad);
  gt.T_base_cam_true.translation() = Eigen::Vector3d(1.6, 0.01, 1.7);
  gt.T_base_cam_rough = gt.T_base_cam_true;
  for (int k = 0; k < kStanding + kMoving; ++k) {
    GroundTruthFrame frame;
    frame.stamp = 50.0 + 0.05 * k;
    const double x = k < kStanding ? 0.0 : 0.5 * (k - kStanding + 1);  // 10 m/s after standing
    frame.T_map_base_true.translation() = Eigen::Vector3d(x, 0.0, 0.0);
    frame.T_map_base_odom = frame.T_map_base_true;
    // The odometry wanders 0.3 m while standing, and is 0.1 m off while moving.
    frame.T_map_base_odom.translation().y() += k < kStanding ? 0.3 : 0.1;
    gt.frames.push_back(frame);
  }
  return gt;
}

// A map whose trajectory is the truth shifted by `standing_m` while standing and `moving_m`
// while moving (across the heading).
VectorMap MapWithPoses(const GroundTruth& gt, double standing_m, double moving_m) {
  VectorMap map;
  map.T_base_cam = map.T_base_cam_initial = gt.T_base_cam_true;
  for (std::size_t k = 0; k < gt.frames.size(); ++k) {
    StampedPose pose{gt.frames[k].stamp, gt.frames[k].T_map_base_true};
    pose.T_map_base.translation().y() += static_cast<int>(k) < kStanding ? standing_m : moving_m;
    map.trajectory.push_back(pose);
  }
  return map;
}

TEST(EvaluationPoses, MovingFramesLeaveTheStandstillOut) {
  const GroundTruth gt = StandThenDrive();
  const PoseMetrics m = EvaluatePoses(MapWithPoses(gt, 0.02, 0.05), gt, EvaluationOptions());
  // The last standing frame counts too: its neighbours are 0.5 m apart, 0.1 s apart.
  EXPECT_EQ(m.frames_moving, kMoving + 1);
  EXPECT_NEAR(m.trans_err_moving_m_input.mean, (kMoving * 0.1 + 0.3) / (kMoving + 1), 1e-12);
  EXPECT_NEAR(m.trans_err_moving_m.mean, (kMoving * 0.05 + 0.02) / (kMoving + 1), 1e-12);
  // Over every frame the standstill weighs in.
  EXPECT_NEAR(m.trans_err_m_input.mean, (kStanding * 0.3 + kMoving * 0.1) / 60.0, 1e-12);
  ASSERT_EQ(m.frames.size(), 60u);
  EXPECT_FALSE(m.frames.front().moving);
  EXPECT_TRUE(m.frames.back().moving);

  EvaluationOptions slow;
  slow.pose_moving_min_speed_mps = 20.0;  // faster than the drive: nothing moves
  const PoseMetrics none = EvaluatePoses(MapWithPoses(gt, 0.02, 0.05), gt, slow);
  EXPECT_EQ(none.frames_moving, 0);
  EXPECT_TRUE(std::isnan(none.trans_err_moving_m.mean));
  const nlohmann::json j = MetricsToJson(EvaluateMap(MapWithPoses(gt, 0.0, 0.0), gt, slow));
  EXPECT_TRUE(j["pose_trans_err_moving_m"].is_null());
}

TEST(EvaluationPoses, WithoutATrajectoryTheOdometryIsStillMeasuredWhileMoving) {
  const GroundTruth gt = StandThenDrive();
  VectorMap map = MapWithPoses(gt, 0.0, 0.0);
  map.trajectory.clear();
  const nlohmann::json j = MetricsToJson(EvaluateMap(map, gt, EvaluationOptions()));
  EXPECT_EQ(j["pose_frames_moving"], kMoving + 1);
  EXPECT_TRUE(j["pose_trans_err_moving_m"].is_null());
  EXPECT_NEAR(j["pose_trans_err_moving_m_input"].get<double>(),
              (kMoving * 0.1 + 0.3) / (kMoving + 1), 1e-12);
}

TEST(EvaluationPoses, TheTrueExtrinsicInConfigFormRebuildsTheTruth) {
  const GroundTruth gt = StandThenDrive();
  const ExtrinsicMetrics m = EvaluateExtrinsic(MapWithPoses(gt, 0.0, 0.0), gt, {});
  const Eigen::Vector3d rpy = m.true_rpy_deg * kDegToRad;
  const Eigen::Matrix3d R_base_cam = RotationFromRpy(rpy.x(), rpy.y(), rpy.z());
  EXPECT_TRUE(R_base_cam.isApprox(gt.T_base_cam_true.linear(), 1e-12));
  EXPECT_NEAR(m.true_rpy_deg.x(), -91.0, 1e-9);
  EXPECT_NEAR(m.true_rpy_deg.z(), -89.5, 1e-9);
  EXPECT_TRUE(m.true_xyz_m.isApprox(Eigen::Vector3d(1.6, 0.01, 1.7)));
  const nlohmann::json j = MetricsToJson(EvaluateMap(MapWithPoses(gt, 0.0, 0.0), gt, {}));
  EXPECT_NEAR(j["extrinsic_true_rpy_deg"][1].get<double>(), 2.0, 1e-9);
  EXPECT_NEAR(j["extrinsic_true_xyz_m"][2].get<double>(), 1.7, 1e-12);
}

}  // namespace
}  // namespace ipm_road_mapper
