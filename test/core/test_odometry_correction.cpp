// The correction of the odometry after a solve (odometry_correction.h): fitted over the
// solved frames, it is the exact correction when they agree, and on odometry with a
// per-message jitter it is much closer to the true correction than one frame's correction,
// which carries that frame's own error to every frame after it.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "ipm_road_mapper/core/mapper/odometry_correction.h"

namespace ipm_road_mapper {
namespace {

Eigen::Isometry3d Pose(double x, double y, double yaw) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, y, 0.0);
  return T;
}

// 40 frames at 10 m/s on a 200 m circle, 300 m from the odometry's origin (a lever arm that
// turns a rotation error into a translation error), solved exactly; the odometry is the truth
// moved by T_map_odom^-1 plus a per-frame jitter of `jitter_m` per axis and `jitter_rad`.
struct Drive {
  std::vector<FrameRecord> frames;
  Eigen::Isometry3d T_map_odom = Pose(0.4, -0.3, 0.003);
};

Drive MakeDrive(double jitter_m, double jitter_rad, std::uint32_t seed) {
  Drive d;
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  for (int i = 0; i < 40; ++i) {
    const double yaw = 0.5 * i / 200.0;
    const Eigen::Isometry3d T_true =
        Pose(300.0 + 200.0 * std::sin(yaw), 200.0 * (1.0 - std::cos(yaw)), yaw);
    FrameRecord f;
    f.index = static_cast<std::size_t>(i);
    f.stamp = 0.05 * i;
    f.T_map_base = T_true;
    f.T_map_base_odom = d.T_map_odom.inverse() * T_true *
                        Pose(jitter_m * noise(rng), jitter_m * noise(rng), jitter_rad * noise(rng));
    d.frames.push_back(f);
  }
  return d;
}

std::vector<std::size_t> All(const Drive& d) {
  std::vector<std::size_t> solved;
  for (const FrameRecord& f : d.frames) solved.push_back(f.index);
  return solved;
}

TEST(OdometryCorrection, ExactWhenTheSolvedFramesAgree) {
  const Drive d = MakeDrive(0.0, 0.0, 1);
  EXPECT_TRUE(FitOdometryCorrection(d.frames, All(d)).isApprox(d.T_map_odom, 1e-9));
  EXPECT_TRUE(FitOdometryCorrection(d.frames, {7}).isApprox(d.T_map_odom, 1e-9));
  EXPECT_TRUE(FitOdometryCorrection(d.frames, {}).isApprox(Eigen::Isometry3d::Identity()));
}

// What the newest frame's carried pose errs by (the frame after the solved ones, carried by
// the correction): public_road's jitter, 8 cm and 0.125 deg per axis.
TEST(OdometryCorrection, AveragesTheJitterThatOneFrameCarries) {
  double error_fitted = 0.0, error_one = 0.0;
  const int runs = 20;
  for (int run = 0; run < runs; ++run) {
    const Drive d = MakeDrive(0.08, 0.125 * M_PI / 180.0, 100 + run);
    const Eigen::Isometry3d T_odom_next = d.T_map_odom.inverse() * d.frames.back().T_map_base;
    const Eigen::Isometry3d T_true_next = d.frames.back().T_map_base;
    const Eigen::Isometry3d fitted = FitOdometryCorrection(d.frames, All(d));
    const Eigen::Isometry3d one = FitOdometryCorrection(d.frames, {d.frames.size() - 1});
    error_fitted += ((fitted * T_odom_next).translation() - T_true_next.translation()).norm();
    error_one += ((one * T_odom_next).translation() - T_true_next.translation()).norm();
  }
  error_fitted /= runs;
  error_one /= runs;
  EXPECT_GT(error_one, 0.07);  // one frame's jitter: ~0.1 m mean
  EXPECT_LT(error_fitted, 0.3 * error_one) << error_fitted << " vs " << error_one;
}

}  // namespace
}  // namespace ipm_road_mapper
