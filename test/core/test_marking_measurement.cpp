// MeasureCornersOnPlane: exact on the marking's true plane where flat-ground IPM is biased,
// in the reference's corner order, and false when the plane is behind the outline's rays.
#include <gtest/gtest.h>

#include <cmath>

#include "common/test_scene.h"
#include "ipm_road_mapper/core/frontend/marking_measurement.h"
#include "ipm_road_mapper/core/geometry/rigid_transform.h"

namespace ipm_road_mapper {
namespace {

constexpr double kDeg = M_PI / 180.0;

// Camera 1.5 m above the map origin looking along +x, pitched down 4 deg.
Eigen::Isometry3d CameraPose() { return test::MountedCamera(0.0, 4.0 * kDeg, 0.0); }

// A 4 x 0.5 m stripe centered 12 m ahead, 1 m left, turned 5 deg, on a road plane that
// rises 1 deg ahead and 0.5 deg to the left, 8 cm above z = 0 at the stripe: what body pitch
// and waves do to base_link's view of the road.
struct Scene {
  PinholeCamera camera{test::Intrinsics1280x720(639.5, 359.5, test::kMildDistortion)};
  Eigen::Vector3d axis;
  Eigen::Isometry3d T_map_cam = CameraPose();
  RoadPlane plane;
  std::array<Eigen::Vector3d, 4> corners;  // counter-clockwise seen from above
  std::vector<Eigen::Vector2d> outline_uv;
  std::array<Eigen::Vector2d, 4> corners_uv;
  Scene() {
    const Eigen::Vector3d center(13.5, 1.0, 0.08);
    plane.point = center;
    plane.normal = Eigen::Vector3d(-std::tan(1.0 * kDeg), -std::tan(0.5 * kDeg), 1.0).normalized();
    axis = Eigen::Vector3d(std::cos(5 * kDeg), std::sin(5 * kDeg), 0.0);
    axis = (axis - plane.normal * plane.normal.dot(axis)).normalized();
    const Eigen::Vector3d across = plane.normal.cross(axis);
    const double a[4] = {-2.0, 2.0, 2.0, -2.0}, c[4] = {-0.25, -0.25, 0.25, 0.25};
    for (int i = 0; i < 4; ++i) corners[i] = center + a[i] * axis + c[i] * across;
    const Eigen::Isometry3d T_cam_map = T_map_cam.inverse();
    for (int i = 0; i < 4; ++i) {
      EXPECT_TRUE(camera.Project(Eigen::Vector3d(T_cam_map * corners[i]), &corners_uv[i]));
      // The outline: the rectangle's edges, densified (distortion bends them slightly).
      for (int k = 0; k < 20; ++k) {
        const Eigen::Vector3d p = corners[i] + (corners[(i + 1) % 4] - corners[i]) * (k / 20.0);
        Eigen::Vector2d uv;
        EXPECT_TRUE(camera.Project(Eigen::Vector3d(T_cam_map * p), &uv));
        outline_uv.push_back(uv);
      }
    }
  }
};

double MaxPixelError(const std::array<Eigen::Vector2d, 4>& a,
                     const std::array<Eigen::Vector2d, 4>& b) {
  double worst = 0.0;
  for (int i = 0; i < 4; ++i) worst = std::max(worst, (a[i] - b[i]).norm());
  return worst;
}

TEST(MeasureCornersOnPlane, ExactOnTheTruePlaneBiasedOnTheFlatGround) {
  const Scene scene;
  // The reference (the map's estimate, for the order only) is off by decimeters and starts
  // at another corner; the axis is the road's, given horizontal (it is projected).
  std::array<Eigen::Vector3d, 4> reference;
  for (int i = 0; i < 4; ++i) {
    reference[i] = scene.corners[(i + 1) % 4] + Eigen::Vector3d(0.2, -0.1, 0.05);
  }
  const Eigen::Vector3d road_axis(std::cos(5 * kDeg), std::sin(5 * kDeg), 0.0);
  std::array<Eigen::Vector2d, 4> measured;
  ASSERT_TRUE(MeasureCornersOnPlane(scene.camera, scene.T_map_cam, scene.plane, -road_axis,
                                    reference, scene.outline_uv, &measured));
  std::array<Eigen::Vector2d, 4> expected;
  for (int i = 0; i < 4; ++i) expected[i] = scene.corners_uv[(i + 1) % 4];
  EXPECT_LT(MaxPixelError(measured, expected), 1e-6);
  // On base_link's flat ground (what the front end assumes) the same construction misses.
  RoadPlane flat;
  ASSERT_TRUE(MeasureCornersOnPlane(scene.camera, scene.T_map_cam, flat, road_axis, scene.corners,
                                    scene.outline_uv, &measured));
  EXPECT_GT(MaxPixelError(measured, scene.corners_uv), 1.0);
}

TEST(MeasureCornersOnPlane, FailsWhenThePlaneIsBehindTheRays) {
  const Scene scene;
  RoadPlane above;  // a plane above the camera: every downward ray misses it
  above.point = Eigen::Vector3d(0, 0, 3.0);
  std::array<Eigen::Vector2d, 4> measured;
  EXPECT_FALSE(MeasureCornersOnPlane(scene.camera, scene.T_map_cam, above, scene.axis,
                                     scene.corners, scene.outline_uv, &measured));
  EXPECT_FALSE(MeasureCornersOnPlane(scene.camera, scene.T_map_cam, scene.plane, scene.axis,
                                     scene.corners, {}, &measured));
  EXPECT_FALSE(MeasureCornersOnPlane(scene.camera, scene.T_map_cam, scene.plane, scene.plane.normal,
                                     scene.corners, scene.outline_uv, &measured));
}

}  // namespace
}  // namespace ipm_road_mapper
