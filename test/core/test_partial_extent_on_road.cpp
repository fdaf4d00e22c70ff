// The unmeasured side of a marking seen only in partial views, measured again at the end of
// the drive on the road plane from the corrected poses (partial_extent_on_road.h): where the
// views ended on the road, not where flat-ground IPM of a pitched body put that end.
#include <gtest/gtest.h>

#include <cmath>

#include "common/test_scene.h"
#include "ipm_road_mapper/core/geometry/rigid_transform.h"
#include "ipm_road_mapper/core/mapper/partial_extent_on_road.h"

namespace ipm_road_mapper {
namespace {

constexpr double kDeg = M_PI / 180.0;

// A level road driven along x from 0 to 30 m (the vehicle passed the marking), the body
// pitched 0.3 deg nose up in the frame that saw it (frame 0, at x = 0); a 5 x 1.5 m marking
// 3-4.5 m left of the path at x = 14-19 m, of which that view shows x >= 15 m (the rest is
// out of the image at the side): its near end (side 3) is cut, the other sides measured.
struct Scene {
  MapStore store{6.0};
  PinholeCamera camera{test::Intrinsics1280x720()};
  Eigen::Isometry3d T_base_cam =
      test::MountedCamera(0.0, 4.0 * kDeg, 0.0, Eigen::Vector3d(1.5, 0.0, 1.5));
  MarkingElement element;

  Scene() {
    for (int i = 0; i <= 60; ++i) {
      Eigen::Isometry3d T_map_base = test::PlanarPose(0.5 * i, 0.0, 0.0);
      if (i == 0) T_map_base.linear() = RotationFromRpy(0.0, -0.3 * kDeg, 0.0);
      store.AddFrame(0.05 * i, T_map_base);
    }
    MarkingMeasurement view;
    view.frame_index = 0;
    const Eigen::Isometry3d T_cam_map = (store.frames()[0].T_map_base * T_base_cam).inverse();
    for (const Eigen::Vector3d& p :
         {Eigen::Vector3d(15.0, 3.0, 0.0), Eigen::Vector3d(19.0, 3.0, 0.0),
          Eigen::Vector3d(19.0, 4.5, 0.0), Eigen::Vector3d(15.0, 4.5, 0.0)}) {
      Eigen::Vector2d uv;
      EXPECT_TRUE(camera.Project(Eigen::Vector3d(T_cam_map * p), &uv));
      view.outline_uv.push_back(uv);
    }
    view.side_measured = {{true, true, true, false}};
    element.history.push_back(view);
    element.side_measured = {{true, true, true, false}};
    // The near end where a flat-ground union put it: 1.2 m too near.
    element.corners_map = {Eigen::Vector3d(13.8, 3.0, 0.0), Eigen::Vector3d(19.0, 3.0, 0.0),
                           Eigen::Vector3d(19.0, 4.5, 0.0), Eigen::Vector3d(13.8, 4.5, 0.0)};
  }
};

TEST(PartialExtentOnRoad, PutsTheCutSideWhereTheViewEndedOnTheRoad) {
  Scene scene;
  const auto corners =
      PartialExtentOnRoad(scene.camera, scene.T_base_cam, scene.store, scene.element);
  ASSERT_TRUE(corners.has_value());
  // Side 3 (corners 3 and 0) moved to x = 15 m; the measured sides stay as they were.
  EXPECT_NEAR((*corners)[0].x(), 15.0, 0.02);
  EXPECT_NEAR((*corners)[3].x(), 15.0, 0.02);
  EXPECT_NEAR((*corners)[0].y(), 3.0, 1e-9);
  EXPECT_NEAR((*corners)[3].y(), 4.5, 1e-9);
  for (int c : {1, 2}) EXPECT_EQ((*corners)[c], scene.element.corners_map[c]);
  // The same view through its own pitched base_link plane (flat-ground IPM) ends elsewhere:
  // that is what the re-measurement removes.
  const Eigen::Isometry3d T_map_cam = scene.store.frames()[0].T_map_base * scene.T_base_cam;
  const Eigen::Vector2d xy =
      scene.camera.UndistortToNormalized(scene.element.history[0].outline_uv[0]);
  const Eigen::Vector3d ray = T_map_cam.linear() * Eigen::Vector3d(xy.x(), xy.y(), 1.0);
  const Eigen::Vector3d up_base = scene.store.frames()[0].T_map_base.linear().col(2);
  const double t =
      up_base.dot(scene.store.frames()[0].T_map_base.translation() - T_map_cam.translation()) /
      up_base.dot(ray);
  EXPECT_GT(std::abs((T_map_cam.translation() + t * ray).x() - 15.0), 0.2);
}

TEST(PartialExtentOnRoad, LeavesCompleteAndPrunedElementsAlone) {
  Scene complete;
  complete.element.side_measured = {{true, true, true, true}};
  EXPECT_FALSE(
      PartialExtentOnRoad(complete.camera, complete.T_base_cam, complete.store, complete.element));
  // A pruned history no longer holds every view: their union is not known.
  Scene pruned;
  pruned.element.pruned = 3;
  EXPECT_FALSE(PartialExtentOnRoad(pruned.camera, pruned.T_base_cam, pruned.store, pruned.element));
}

}  // namespace
}  // namespace ipm_road_mapper
