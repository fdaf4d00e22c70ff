// The map store: its road-surface query is RoadSurfaceNear's over every frame (through the
// index, also after pose corrections), the road direction comes from the nearest lane, and
// clearing keeps element ids unique.
#include <gtest/gtest.h>

#include <random>

#include "ipm_road_mapper/core/geometry/rigid_transform.h"
#include "ipm_road_mapper/core/mapper/map_store.h"

namespace ipm_road_mapper {
namespace {

Eigen::Isometry3d Pose(double x, double y, double z, double roll, double pitch, double yaw) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = RotationFromRpy(roll, pitch, yaw);
  T.translation() = Eigen::Vector3d(x, y, z);
  return T;
}

TEST(MapStore, RoadSurfaceIsRoadSurfaceNearOverAllFrames) {
  std::mt19937 rng(3);
  std::normal_distribution<double> tilt(0.0, 0.01), height(0.0, 0.05), lateral(0.0, 0.3);
  MapStore store(4.0);
  std::vector<Eigen::Isometry3d> poses;
  for (int i = 0; i < 400; ++i) {
    const double s = 0.5 * i;
    const Eigen::Isometry3d T =
        Pose(s * std::cos(0.003 * s), 60.0 * std::sin(0.003 * s) + lateral(rng), height(rng),
             tilt(rng), tilt(rng), 0.003 * s);
    poses.push_back(T);
    store.AddFrame(100.0 + 0.05 * i, T);
  }
  for (int i = 0; i < 400; i += 7) {  // corrected poses move
    poses[i].translation() += Eigen::Vector3d(lateral(rng), lateral(rng), 0.0);
    store.SetFramePose(i, poses[i]);
  }
  for (int q = 0; q < 100; ++q) {
    const Eigen::Vector3d p(2.5 * q - 20.0, lateral(rng) * 10.0, 0.0);
    const RoadSurfaceEstimate expected = RoadSurfaceNear(poses, p, 4.0);
    const RoadSurfaceEstimate got = store.RoadSurfaceAt(p);
    EXPECT_EQ(got.frames, expected.frames);
    EXPECT_DOUBLE_EQ(got.distance_m, expected.distance_m);
    EXPECT_TRUE(got.plane.point.isApprox(expected.plane.point, 1e-12));
    EXPECT_TRUE(got.plane.normal.isApprox(expected.plane.normal, 1e-12));
  }
  EXPECT_EQ(store.frames()[7].T_map_base.translation(), poses[7].translation());
  EXPECT_EQ(store.frames()[7].T_map_base_odom.translation().x(), 3.5 * std::cos(0.0105));
}

TEST(MapStore, RoadDirectionIsTheNearestLanesTangent) {
  MapStore store(4.0);
  EXPECT_EQ(store.RoadDirectionAt(Eigen::Vector3d::Zero()), Eigen::Vector3d::Zero());
  LaneElement along_x;
  for (int i = -1; i <= 10; ++i) along_x.control_points_map.emplace_back(3.0 * i, 2.0, 0.0);
  LaneElement diagonal;
  for (int i = -1; i <= 10; ++i) diagonal.control_points_map.emplace_back(3.0 * i, 3.0 * i - 9.0, 0.0);
  store.lanes().push_back(along_x);
  store.lanes().push_back(diagonal);
  const Eigen::Vector3d near_x = store.RoadDirectionAt(Eigen::Vector3d(10.0, 2.5, 0.0));
  EXPECT_NEAR(std::abs(near_x.x()), 1.0, 1e-6);
  const Eigen::Vector3d near_diagonal = store.RoadDirectionAt(Eigen::Vector3d(20.0, 11.5, 0.0));
  EXPECT_NEAR(std::abs(near_diagonal.x()), std::sqrt(0.5), 1e-3);
  // Farther than 8 m from every lane: no direction.
  EXPECT_EQ(store.RoadDirectionAt(Eigen::Vector3d(0.0, -30.0, 0.0)), Eigen::Vector3d::Zero());
}

TEST(MapStore, ClearDropsEverythingButIdsStayUnique) {
  MapStore store(4.0);
  store.AddFrame(1.0, Eigen::Isometry3d::Identity());
  const std::uint64_t first = store.NewId();
  store.markings().emplace_back();
  store.Clear();
  EXPECT_TRUE(store.frames().empty());
  EXPECT_TRUE(store.markings().empty());
  EXPECT_GT(store.NewId(), first);
  EXPECT_EQ(store.RoadSurfaceAt(Eigen::Vector3d::Zero()).frames, 0);
  EXPECT_EQ(store.AddFrame(2.0, Eigen::Isometry3d::Identity()).index, 0u);
}

}  // namespace
}  // namespace ipm_road_mapper
