// Tests of the front end's ground from the trajectory (trajectory_road_plane.h) and of IPM onto
// it: a pitched body on flat ground maps a far pixel to the right point, a grade and a cross
// slope are the road's, and a flat 2D odometry gives base_link's plane, and so today's IPM,
// exactly.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "common/test_scene.h"
#include "common/units.h"
#include "ipm_road_mapper/core/geometry/ipm.h"
#include "ipm_road_mapper/core/geometry/rigid_transform.h"
#include "ipm_road_mapper/core/geometry/trajectory_road_plane.h"

namespace ipm_road_mapper {
namespace {

constexpr double kSpeedMps = 10.0;
constexpr double kRateHz = 20.0;

// The trajectory's last `seconds` up to t = 0 along +x at kSpeedMps on a road of height
// grade * x + cross * y, the body turned by road + body_pitch(t) / body_roll(t).
template <typename PitchOfT, typename RollOfT>
std::vector<StampedPose> Drive(double seconds, double grade, double cross, PitchOfT body_pitch,
                               RollOfT body_roll) {
  std::vector<StampedPose> poses;
  for (double t = -seconds; t <= 1e-9; t += 1.0 / kRateHz) {
    const double x = kSpeedMps * t;
    StampedPose pose;
    pose.stamp = 100.0 + t;
    pose.T_map_base.linear() =
        RotationFromRpy(std::atan(cross) + body_roll(t), -std::atan(grade) + body_pitch(t), 0.0);
    pose.T_map_base.translation() = Eigen::Vector3d(x, 0.0, grade * x);
    poses.push_back(pose);
  }
  return poses;
}

double Zero(double) { return 0.0; }

Ipm MakeIpm(const RoadPlane& ground) {
  return Ipm(PinholeCamera(test::Intrinsics1280x720()),
             test::MountedCamera(0.0, 4.0 * kDeg, 0.0, {1.5, 0.0, 1.5}), 1000.0, ground);
}

// The map point the pixel of `p_map` maps to, through IPM onto `ground` in the newest pose.
Eigen::Vector3d Reprojected(const StampedPose& newest, const RoadPlane& ground,
                            const Eigen::Vector3d& p_map) {
  const Ipm ipm = MakeIpm(ground);
  Eigen::Vector2d uv;
  EXPECT_TRUE(ipm.BaseToPixel(newest.T_map_base.inverse() * p_map, &uv));
  Eigen::Vector3d p_base;
  EXPECT_EQ(ipm.PixelToGround(uv, &p_base), IpmStatus::kOk);
  return newest.T_map_base * p_base;
}

TEST(TrajectoryRoadPlane, NoTrajectoryIsBaseLinksPlane) {
  const RoadPlane plane = RoadPlaneFromTrajectory({}, TrajectoryRoadPlaneOptions());
  EXPECT_EQ(plane.normal, Eigen::Vector3d::UnitZ());
  EXPECT_EQ(plane.point, Eigen::Vector3d::Zero());
}

TEST(TrajectoryRoadPlane, FlatTwoDimensionalOdometryGivesTodaysIpmExactly) {
  // A planar odometry (z = 0, no roll or pitch) along a curve.
  std::vector<StampedPose> poses;
  for (int k = 0; k < 60; ++k) {
    const double yaw = 0.01 * k;
    poses.push_back({100.0 + 0.05 * k, test::PlanarPose(0.5 * k, 0.02 * k * k, yaw)});
  }
  const RoadPlane plane = RoadPlaneFromTrajectory(poses, TrajectoryRoadPlaneOptions());
  EXPECT_EQ(plane.normal, Eigen::Vector3d::UnitZ());
  EXPECT_EQ(plane.point, Eigen::Vector3d::Zero());
  const Ipm on_plane = MakeIpm(plane);
  const Ipm today(on_plane.camera(), on_plane.T_base_cam(), on_plane.max_range_m());
  EXPECT_TRUE(on_plane.flat());
  for (double v = 380.0; v < 720.0; v += 17.0) {
    for (double u = 0.0; u < 1280.0; u += 61.0) {
      Eigen::Vector3d a = Eigen::Vector3d::Constant(-1.0), b = a;
      ASSERT_EQ(on_plane.PixelToGround({u, v}, &a), today.PixelToGround({u, v}, &b));
      EXPECT_EQ(a, b);
    }
  }
  EXPECT_EQ(on_plane.OnGround({12.0, -3.0}), Eigen::Vector3d(12.0, -3.0, 0.0));
}

TEST(TrajectoryRoadPlane, PitchedBodyOnFlatGroundMapsAFarPixelOntoTheRoad) {
  // The body pitched 0.3 deg nose down, held, on flat ground: a point 30 m ahead and 3.5 m to
  // the left is seen through the pitched camera.
  const auto pitch = [](double) { return 0.3 * kDeg; };
  const std::vector<StampedPose> poses = Drive(3.0, 0.0, 0.0, pitch, Zero);
  const RoadPlane plane = RoadPlaneFromTrajectory(poses, TrajectoryRoadPlaneOptions());
  const Eigen::Vector3d far_map(poses.back().T_map_base.translation().x() + 30.0, 3.5, 0.0);
  const Eigen::Vector3d on_road = Reprojected(poses.back(), plane, far_map);
  EXPECT_LT((on_road - far_map).norm(), 1e-6);
  // base_link's own plane (the body's) puts it metres off along and decimetres across.
  const Eigen::Vector3d flat = Reprojected(poses.back(), RoadPlane(), far_map);
  EXPECT_GT(std::abs(flat.x() - far_map.x()), 2.0);
  EXPECT_GT(std::abs(flat.y() - far_map.y()), 0.2);
}

TEST(TrajectoryRoadPlane, OscillatingBodyAndHeaveAverageOut) {
  // The synthetic drives' suspension: pitch 0.3 deg at 1.1 Hz (at its largest now), roll
  // 0.1 deg at 0.7 Hz.
  const auto pitch = [](double t) { return 0.3 * kDeg * std::cos(2.0 * M_PI * 1.1 * t); };
  const auto roll = [](double t) { return 0.1 * kDeg * std::sin(2.0 * M_PI * 0.7 * t + 1.3); };
  std::vector<StampedPose> poses = Drive(3.0, 0.0, 0.0, pitch, roll);
  for (StampedPose& p : poses) {  // heave 1 cm at 1.5 Hz
    p.T_map_base.translation().z() += 0.01 * std::sin(2.0 * M_PI * 1.5 * (p.stamp - 100.0));
  }
  const RoadPlane plane = RoadPlaneFromTrajectory(poses, TrajectoryRoadPlaneOptions());
  const Eigen::Vector3d normal_map = poses.back().T_map_base.linear() * plane.normal;
  EXPECT_LT(std::acos(std::min(1.0, normal_map.z())), 0.1 * kDeg);
  // The body's instantaneous plane is off by its pitch.
  const Eigen::Vector3d body_normal = poses.back().T_map_base.linear().col(2);
  EXPECT_GT(std::acos(body_normal.z()), 0.2 * kDeg);
}

TEST(TrajectoryRoadPlane, GradeAndCrossSlopeAreTheRoads) {
  // A 5 % grade and a 3 % cross slope (left side up), the body pitched on top of it.
  const double grade = 0.05, cross = 0.03;
  const auto pitch = [](double) { return 0.3 * kDeg; };
  const std::vector<StampedPose> poses = Drive(3.0, grade, cross, pitch, Zero);
  const RoadPlane plane = RoadPlaneFromTrajectory(poses, TrajectoryRoadPlaneOptions());
  const Eigen::Vector3d normal_map = poses.back().T_map_base.linear() * plane.normal;
  // The road z = grade x + cross y: its normal (up to the body's RPY construction, which
  // differs by cross * grade^2 / 2).
  const Eigen::Vector3d expected = Eigen::Vector3d(-grade, -cross, 1.0).normalized();
  EXPECT_LT(std::acos(std::min(1.0, normal_map.dot(expected))), 0.01 * kDeg)
      << normal_map.transpose() << " vs " << expected.transpose();
  // A point 25 m ahead on the grade's plane (the line at y = 0, where the cross slope adds
  // nothing) maps onto itself.
  const Eigen::Vector3d p0 = poses.back().T_map_base.translation();
  const Eigen::Vector3d ahead_map = p0 + 25.0 * Eigen::Vector3d(1.0, 0.0, grade).normalized();
  EXPECT_LT((Reprojected(poses.back(), plane, ahead_map) - ahead_map).norm(), 1e-3);
}

TEST(TrajectoryRoadPlane, StandingVehicleTakesTheBodysMeanAttitude) {
  // No path to fit a grade to: the mean of the body's normal over the window.
  std::vector<StampedPose> poses;
  for (int k = 0; k < 30; ++k) {  // all within the 1.5 s window
    StampedPose pose;
    pose.stamp = 100.0 + 0.05 * k;
    pose.T_map_base.linear() = RotationFromRpy(0.0, (k % 2 ? 0.2 : 0.4) * kDeg, 0.0);
    poses.push_back(pose);
  }
  const RoadPlane plane = RoadPlaneFromTrajectory(poses, TrajectoryRoadPlaneOptions());
  const Eigen::Vector3d normal_map = poses.back().T_map_base.linear() * plane.normal;
  EXPECT_NEAR(std::atan2(normal_map.x(), normal_map.z()), 0.3 * kDeg, 1e-3 * kDeg);
}

TEST(IpmOnARoadPlane, PointsOfThePlaneAreRecoveredAndOnGroundIsOnIt) {
  RoadPlane ground;
  ground.normal = Eigen::Vector3d(-0.04, 0.02, 1.0).normalized();
  ground.point = Eigen::Vector3d(0.0, 0.0, -0.01);
  const Ipm ipm = MakeIpm(ground);
  EXPECT_FALSE(ipm.flat());
  int tested = 0;
  for (double x = 4.0; x <= 40.0; x += 3.0) {
    for (double y = -6.0; y <= 6.0; y += 1.5) {
      const Eigen::Vector3d p = ipm.OnGround({x, y});
      EXPECT_NEAR(ground.normal.dot(p - ground.point), 0.0, 1e-12);
      Eigen::Vector2d uv;
      if (!ipm.BaseToPixel(p, &uv) || uv.x() < 0 || uv.x() > 1279 || uv.y() < 0 || uv.y() > 719) {
        continue;
      }
      Eigen::Vector3d back;
      ASSERT_EQ(ipm.PixelToGround(uv, &back), IpmStatus::kOk);
      EXPECT_LT((back - p).norm(), 1e-8);
      ++tested;
    }
  }
  EXPECT_GT(tested, 30);
  // Above the plane's horizon (the top row looks up): no ground point.
  Eigen::Vector3d p;
  EXPECT_EQ(ipm.PixelToGround({640.0, 0.0}, &p), IpmStatus::kAboveHorizon);
}

}  // namespace
}  // namespace ipm_road_mapper
