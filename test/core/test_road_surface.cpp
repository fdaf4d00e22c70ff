// The road surface from the vehicle's poses: averaging the frames near a point removes the
// body's pitch oscillation; a point no frame has passed gets the closest frame's plane and
// its distance. A pixel's ray onto a plane. And the pose-uncertainty whitening of the map
// step's residuals.
#include <gtest/gtest.h>

#include <cmath>

#include "common/test_scene.h"
#include "ipm_road_mapper/core/backend/residuals/pose_uncertainty.h"
#include "ipm_road_mapper/core/geometry/rigid_transform.h"
#include "ipm_road_mapper/core/geometry/road_surface.h"

namespace ipm_road_mapper {
namespace {

constexpr double kDeg = M_PI / 180.0;

// A drive along x on a road with a 2 % grade, the body pitching +-0.3 deg at 1.1 Hz (10 m/s,
// a pose every 0.5 m).
std::vector<Eigen::Isometry3d> PitchingDrive() {
  std::vector<Eigen::Isometry3d> poses;
  const double grade = std::atan(0.02);
  for (int k = 0; k < 100; ++k) {
    const double x = 0.5 * k, t = 0.05 * k;
    const double body = 0.3 * kDeg * std::sin(2.0 * M_PI * 1.1 * t);
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = RotationFromRpy(0.0, -grade + body, 0.0);  // nose up on the grade: -pitch
    T.translation() = Eigen::Vector3d(x, 0.0, 0.02 * x);
    poses.push_back(T);
  }
  return poses;
}

TEST(RoadSurfaceNear, AveragesThePitchOscillationOut) {
  const auto poses = PitchingDrive();
  const Eigen::Vector3d p(25.0, 1.5, 0.5);  // a marking corner beside the path
  const RoadSurfaceEstimate road = RoadSurfaceNear(poses, p, 6.0);
  EXPECT_GT(road.frames, 10);
  EXPECT_NEAR(road.distance_m, 1.5, 0.01);
  // The true road there: z = 0.02 x, normal (-0.02, 0, 1) normalized.
  const Eigen::Vector3d normal_true = Eigen::Vector3d(-0.02, 0.0, 1.0).normalized();
  // 1.3 periods of the oscillation in the radius: a part remains (0.06 deg here).
  EXPECT_LT(std::acos(std::min(1.0, road.plane.normal.dot(normal_true))), 0.1 * kDeg);
  const double height = road.plane.normal.dot(Eigen::Vector3d(25.0, 1.5, 0.5) - road.plane.point);
  EXPECT_NEAR(height, 0.0, 0.005);
  // One frame's plane (radius 0) carries its body pitch: up to 0.3 deg off.
  const RoadSurfaceEstimate one = RoadSurfaceNear(poses, p, 0.0);
  EXPECT_EQ(one.frames, 1);
  EXPECT_GT(std::acos(std::min(1.0, one.plane.normal.dot(normal_true))), 0.1 * kDeg);
}

TEST(RoadSurfaceNear, ExtrapolatesTheClosestFrameAheadAndHandlesNoPoses) {
  const auto poses = PitchingDrive();
  const RoadSurfaceEstimate ahead = RoadSurfaceNear(poses, Eigen::Vector3d(70.0, 0.0, 1.4), 6.0);
  EXPECT_EQ(ahead.frames, 1);
  EXPECT_NEAR(ahead.distance_m, 70.0 - 49.5, 1e-9);
  EXPECT_TRUE((ahead.plane.point - poses.back().translation()).isZero());
  EXPECT_EQ(RoadSurfaceNear({}, Eigen::Vector3d::Zero(), 6.0).frames, 0);
}

TEST(RoadSurfaceNear, GivesThePointsOffsetAcrossTheClosestFrame) {
  auto poses = PitchingDrive();
  for (Eigen::Isometry3d& T : poses) {  // heading +90 deg: base_link y is map -x
    T.linear() = RotationFromRpy(0.0, 0.0, M_PI / 2.0);
    T.translation() = Eigen::Vector3d(0.0, T.translation().x(), 0.0);
  }
  EXPECT_NEAR(RoadSurfaceNear(poses, Eigen::Vector3d(-5.25, 20.1, 0.0), 6.0).lateral_m, 5.25, 1e-9);
  EXPECT_NEAR(RoadSurfaceNear(poses, Eigen::Vector3d(1.75, 20.0, 0.0), 6.0).lateral_m, -1.75, 1e-9);
}

TEST(PoseUncertaintyWhitening, IsThePixelSigmaForExactPosesAndWeakerOtherwise) {
  const PinholeCamera camera(test::Intrinsics1280x720(639.5, 359.5));
  const Eigen::Isometry3d T_base_cam = test::MountedCamera(0.0, 4.0 * kDeg, 0.0);
  const Eigen::Isometry3d T_map_base = Eigen::Isometry3d::Identity();
  const Eigen::Vector3d near(8.0, 1.0, 0.0), far(25.0, 1.0, 0.0);
  const Eigen::Matrix2d exact = residuals::PoseUncertaintyWhitening(
      camera, T_map_base, T_base_cam, near, 2.0, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
  EXPECT_LT((exact - Eigen::Matrix2d::Identity() / 2.0).norm(), 1e-12);
  // 0.1 m of longitudinal pose error moves a ground point 8 m ahead by ~2.5 px in v: its
  // vertical information drops; 25 m ahead much less (the pixel shift falls as 1/d^2).
  const Eigen::Vector3d sigma_t(0.1, 0.0, 0.0);
  const Eigen::Matrix2d W_near = residuals::PoseUncertaintyWhitening(
      camera, T_map_base, T_base_cam, near, 2.0, sigma_t, Eigen::Vector3d::Zero());
  const Eigen::Matrix2d W_far = residuals::PoseUncertaintyWhitening(
      camera, T_map_base, T_base_cam, far, 2.0, sigma_t, Eigen::Vector3d::Zero());
  const double info_near = (W_near.transpose() * W_near)(1, 1);
  const double info_far = (W_far.transpose() * W_far)(1, 1);
  EXPECT_LT(info_near, 0.5 * 0.25);  // at least halved from 1 / 2^2
  EXPECT_GT(info_far, info_near);
  EXPECT_LE(info_far, 0.25 + 1e-12);
}

TEST(PixelOntoPlane, MeetsThePlaneAheadAndNeverAboveTheHorizonOrBehind) {
  const PinholeCamera camera(test::Intrinsics1280x720());
  const Eigen::Isometry3d T_map_cam =
      test::MountedCamera(0.0, 4.0 * kDeg, 0.0, Eigen::Vector3d(1.5, 0.0, 1.5));
  const RoadPlane road{Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ()};
  const Eigen::Vector3d ahead(20.0, 2.0, 0.0);
  Eigen::Vector2d uv;
  ASSERT_TRUE(camera.Project(Eigen::Vector3d(T_map_cam.inverse() * ahead), &uv));
  Eigen::Vector3d p_map;
  ASSERT_TRUE(PixelOntoPlane(camera, T_map_cam, road, uv, &p_map));
  EXPECT_LT((p_map - ahead).norm(), 1e-9);
  // A pixel above the horizon, a plane above the camera (met behind it), a NaN pixel.
  EXPECT_FALSE(PixelOntoPlane(camera, T_map_cam, road, Eigen::Vector2d(640.0, 0.0), &p_map));
  const RoadPlane above{Eigen::Vector3d(0.0, 0.0, 3.0), Eigen::Vector3d::UnitZ()};
  EXPECT_FALSE(PixelOntoPlane(camera, T_map_cam, above, uv, &p_map));
  EXPECT_FALSE(PixelOntoPlane(camera, T_map_cam, road, Eigen::Vector2d::Constant(NAN), &p_map));
}

}  // namespace
}  // namespace ipm_road_mapper
