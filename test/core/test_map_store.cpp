// The map store: its road-surface query is RoadSurfaceNear's over every frame (through the
// index, also after pose corrections; beyond the radius, the frames around the closest one),
// the road direction comes from the nearest lane, and clearing keeps element ids unique.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
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
  int aside = 0;
  for (int q = 0; q < 100; ++q) {
    const Eigen::Vector3d p(2.5 * q - 20.0, lateral(rng) * 10.0, 0.0);
    RoadSurfaceEstimate expected = RoadSurfaceNear(poses, p, 4.0);
    const RoadSurfaceEstimate got = store.RoadSurfaceAt(p);
    EXPECT_DOUBLE_EQ(got.distance_m, expected.distance_m);
    if (expected.distance_m > 4.0) {
      // No frame within the radius: the frames around the closest one.
      std::size_t closest = 0;
      for (std::size_t i = 0; i < poses.size(); ++i) {
        if ((poses[i].translation() - p).head<2>().norm() <
            (poses[closest].translation() - p).head<2>().norm()) {
          closest = i;
        }
      }
      expected = RoadSurfaceNear(poses, poses[closest].translation(), 4.0);
      ++aside;
    }
    EXPECT_EQ(got.frames, expected.frames);
    EXPECT_TRUE(got.plane.point.isApprox(expected.plane.point, 1e-12));
    EXPECT_TRUE(got.plane.normal.isApprox(expected.plane.normal, 1e-12));
  }
  EXPECT_GT(aside, 5);  // the fallback was exercised
  EXPECT_EQ(store.frames()[7].T_map_base.translation(), poses[7].translation());
  EXPECT_EQ(store.frames()[7].T_map_base_odom.translation().x(), 3.5 * std::cos(0.0105));
}

TEST(MapStore, RoadSurfaceAsideOfEveryFrameIsTheRoadNotOneInstantOfTheBodysPitch) {
  // A level road driven at 7 m/s (20 Hz), the body pitching 0.3 deg at 1.1 Hz on it, at the
  // top of a swing in the last frame; a point 8 m aside of that frame, beyond the 6 m radius
  // of every frame. The last frame's own plane is pitched 0.3 deg (13 cm at 25 m along); the
  // frames around it average the swing out.
  constexpr double kDeg = M_PI / 180.0;
  constexpr int kFrames = 200;
  const double t_last = 0.05 * (kFrames - 1);
  MapStore store(6.0);
  for (int i = 0; i < kFrames; ++i) {
    const double t = 0.05 * i;
    const double pitch = 0.3 * kDeg * std::cos(2.0 * M_PI * 1.1 * (t - t_last));
    store.AddFrame(t, Pose(7.0 * t, 0.0, 0.0, 0.0, pitch, 0.0));
  }
  const Eigen::Vector3d aside(7.0 * t_last, 8.0, 0.0);
  const RoadSurfaceEstimate road = store.RoadSurfaceAt(aside);
  EXPECT_NEAR(road.distance_m, 8.0, 1e-9);
  EXPECT_GT(road.frames, 10);
  const double tilt_deg = std::acos(std::min(1.0, road.plane.normal.z())) / kDeg;
  EXPECT_LT(tilt_deg, 0.1);  // the last frame alone: 0.3 deg
}

TEST(MapStore, RoadDirectionIsTheNearestLanesTangent) {
  MapStore store(4.0);
  EXPECT_EQ(store.RoadDirectionAt(Eigen::Vector3d::Zero()), Eigen::Vector3d::Zero());
  LaneElement along_x;
  for (int i = -1; i <= 10; ++i) along_x.control_points_map.emplace_back(3.0 * i, 2.0, 0.0);
  LaneElement diagonal;
  for (int i = -1; i <= 10; ++i)
    diagonal.control_points_map.emplace_back(3.0 * i, 3.0 * i - 9.0, 0.0);
  along_x.id = store.NewId();
  diagonal.id = store.NewId();
  for (const LaneElement* lane : {&along_x, &diagonal}) {
    store.lanes().push_back(*lane);
    store.Touch(&store.lanes().back());  // as every writer of a lane does: indexed by place
  }
  const Eigen::Vector3d near_x = store.RoadDirectionAt(Eigen::Vector3d(10.0, 2.5, 0.0));
  EXPECT_NEAR(std::abs(near_x.x()), 1.0, 1e-6);
  const Eigen::Vector3d near_diagonal = store.RoadDirectionAt(Eigen::Vector3d(20.0, 11.5, 0.0));
  EXPECT_NEAR(std::abs(near_diagonal.x()), std::sqrt(0.5), 1e-3);
  // Farther than 8 m from every lane: no direction.
  EXPECT_EQ(store.RoadDirectionAt(Eigen::Vector3d(0.0, -30.0, 0.0)), Eigen::Vector3d::Zero());
}

LaneElement StraightLane(std::uint64_t id, double x0, double x1, double y) {
  LaneElement lane;
  lane.id = id;
  for (double x = x0; x <= x1 + 1e-9; x += 3.0) lane.control_points_map.emplace_back(x, y, 0.0);
  return lane;
}

TEST(MapStore, LanesAreFoundByPlace) {
  MapStore store(4.0);
  EXPECT_TRUE(store.LanesNear(Eigen::Vector3d::Zero(), 50.0).empty());
  for (double x0 : {0.0, 1000.0, 2000.0}) {
    store.lanes().push_back(StraightLane(store.NewId(), x0, x0 + 60.0, 0.0));
    store.Touch(&store.lanes().back());
  }
  EXPECT_EQ(store.LanesNear(Eigen::Vector3d(30.0, 5.0, 0.0), 20.0), std::vector<std::size_t>{0});
  EXPECT_EQ(store.LanesNear(Eigen::Vector3d(2030.0, 0.0, 0.0), 20.0), std::vector<std::size_t>{2});
  EXPECT_TRUE(store.LanesNear(Eigen::Vector3d(500.0, 0.0, 0.0), 20.0).empty());
  // Grown towards a place (only the new points are touched): found there.
  LaneElement& grown = store.lanes()[1];
  const std::size_t before = grown.control_points_map.size();
  for (double x = 1063.0; x <= 1500.0; x += 3.0) grown.control_points_map.emplace_back(x, 0.0, 0.0);
  store.Touch(&grown, before);
  EXPECT_EQ(store.LanesNear(Eigen::Vector3d(1400.0, 0.0, 0.0), 10.0), std::vector<std::size_t>{1});
  // A lane removed from the map is no longer found, and the indices of the others follow.
  store.lanes().erase(store.lanes().begin());
  EXPECT_TRUE(store.LanesNear(Eigen::Vector3d(30.0, 0.0, 0.0), 20.0).empty());
  EXPECT_EQ(store.LanesNear(Eigen::Vector3d(1400.0, 0.0, 0.0), 10.0), std::vector<std::size_t>{0});
  EXPECT_EQ(store.LanesNear(Eigen::Vector3d(2030.0, 0.0, 0.0), 20.0), std::vector<std::size_t>{1});
  // A disc wider than the indexed cells: every lane, ascending.
  EXPECT_EQ(store.LanesNear(Eigen::Vector3d(1000.0, 0.0, 0.0), 1e6),
            (std::vector<std::size_t>{0, 1}));
  store.Clear();
  EXPECT_TRUE(store.LanesNear(Eigen::Vector3d(1400.0, 0.0, 0.0), 10.0).empty());
}

MarkingElement MarkingAt(std::uint64_t id, double x, double y, std::size_t last_frame) {
  MarkingElement m;
  m.id = id;
  m.class_id = 10;
  m.corners_map = {Eigen::Vector3d(x - 1, y - 0.5, 0), Eigen::Vector3d(x + 1, y - 0.5, 0),
                   Eigen::Vector3d(x + 1, y + 0.5, 0), Eigen::Vector3d(x - 1, y + 0.5, 0)};
  m.center_cov_map = 0.04 * Eigen::Matrix2d::Identity();
  m.last_frame = last_frame;
  return m;
}

TEST(MapStore, RetiredMarkingsLeaveTheLiveSetAndAreFoundByPlace) {
  MapStore store(4.0);
  store.markings().push_back(MarkingAt(1, 0.0, 0.0, 10));
  store.markings().push_back(MarkingAt(2, 25.0, 0.0, 50));
  store.markings().push_back(MarkingAt(3, 9.5, 0.5, 12));
  store.markings()[0].retired = store.markings()[1].retired = store.markings()[2].retired = true;
  store.RetireMarkings(20);  // 2 was seen at frame 50: stays live
  ASSERT_EQ(store.markings().size(), 1u);
  EXPECT_EQ(store.markings()[0].id, 2u);
  ASSERT_EQ(store.retired_markings().size(), 2u);
  EXPECT_DOUBLE_EQ(store.max_retired_cov_trace(), 0.08);
  // Across a cell border (cells of 10 m): 3 at x = 9.5 from a query at x = 10.5.
  const std::vector<std::size_t> near = store.RetiredMarkingsNear(Eigen::Vector3d(10.5, 0, 0), 1.5);
  ASSERT_EQ(near.size(), 1u);
  EXPECT_EQ(store.retired_markings()[near[0]].id, 3u);
  EXPECT_EQ(store.RetiredMarkingsNear(Eigen::Vector3d(5.0, 0, 0), 5.1).size(), 2u);
  EXPECT_TRUE(store.RetiredMarkingsNear(Eigen::Vector3d(5.0, 0, 0), std::nan("")).empty());
  // A huge radius scans instead of visiting cells.
  EXPECT_EQ(store.RetiredMarkingsNear(Eigen::Vector3d(5.0, 0, 0), 1e12).size(), 2u);
  // Revived: back among the live ones, and no longer found among the retired.
  const std::size_t live = store.ReviveMarking(near[0]);
  EXPECT_EQ(store.markings()[live].id, 3u);
  EXPECT_TRUE(store.RetiredMarkingsNear(Eigen::Vector3d(10.5, 0, 0), 1.5).empty());
  EXPECT_EQ(store.RetiredMarkingsNear(Eigen::Vector3d(0.0, 0, 0), 1.0).size(), 1u);
}

TEST(MapStore, PruningKeepsCountsAndTheRecentMeasurements) {
  MapStore store(4.0);
  MarkingElement m = MarkingAt(1, 0.0, 0.0, 9);
  for (std::size_t f = 0; f < 10; ++f) {
    MarkingMeasurement measurement;
    measurement.frame_index = f;
    measurement.corners_uv.fill(Eigen::Vector2d::Zero());
    measurement.corners_base.fill(Eigen::Vector3d::Zero());
    m.history.push_back(measurement);
  }
  store.markings().push_back(m);
  LaneElement lane;
  for (std::size_t f = 0; f < 10; ++f) {
    LaneMeasurement measurement;
    measurement.frame_index = f;
    lane.history.push_back(measurement);
  }
  store.lanes().push_back(lane);
  store.PruneHistoriesBefore(6);
  EXPECT_EQ(store.markings()[0].history.size(), 4u);
  EXPECT_EQ(store.markings()[0].history.front().frame_index, 6u);
  EXPECT_EQ(store.markings()[0].Observations(), 10u);
  EXPECT_EQ(store.lanes()[0].history.size(), 4u);
  EXPECT_EQ(store.lanes()[0].Observations(), 10u);
  store.PruneHistoriesBefore(3);  // nothing older left
  EXPECT_EQ(store.markings()[0].Observations(), 10u);
}

TEST(MapStore, TheCorrectionOfASolvedFrameComesOutOnTheFramesAfterIt) {
  MapStore store(4.0);
  for (int i = 0; i < 5; ++i) store.AddFrame(i, Pose(2.0 * i, 0.1 * i, 0.0, 0.0, 0.0, 0.01 * i));
  EXPECT_TRUE(store.T_map_odom().isApprox(Eigen::Isometry3d::Identity()));
  EXPECT_TRUE(store.CorrectedPose(4).isApprox(store.frames()[4].T_map_base_odom));
  // A solve moved frames 1 and 2 by one correction (a shift and a turn), the newest it moved
  // is 2 (odometry_correction.h fits it over both).
  const Eigen::Isometry3d T_map_odom = Pose(0.3, -0.2, 0.01, 0.0, 0.0, 0.02);
  const Eigen::Isometry3d T_1 = T_map_odom * store.frames()[1].T_map_base_odom;
  store.SetFramePose(1, T_1);
  store.SetFramePose(2, T_map_odom * store.frames()[2].T_map_base_odom);
  store.SetCorrectionFrom({});  // nothing moved: no change
  EXPECT_TRUE(store.T_map_odom().isApprox(Eigen::Isometry3d::Identity()));
  EXPECT_EQ(store.corrected_frame(), -1);
  store.SetCorrectionFrom({1, 2});
  EXPECT_EQ(store.corrected_frame(), 2);
  EXPECT_TRUE(store.T_map_odom().isApprox(T_map_odom, 1e-12));
  // Solved frames come out as solved; later ones carry the correction along the odometry.
  EXPECT_TRUE(store.CorrectedPose(1).isApprox(T_1));
  EXPECT_TRUE(store.CorrectedPose(0).isApprox(store.frames()[0].T_map_base_odom));
  for (std::size_t i = 3; i < 5; ++i) {
    EXPECT_TRUE(
        store.CorrectedPose(i).isApprox(T_map_odom * store.frames()[i].T_map_base_odom, 1e-12));
  }
  // A new frame too; its own pose (the estimator's start) and odometry stay the raw odometry.
  const FrameRecord& added = store.AddFrame(5.0, Pose(10.0, 0.5, 0.0, 0.0, 0.0, 0.05));
  EXPECT_TRUE(added.T_map_base_odom.isApprox(Pose(10.0, 0.5, 0.0, 0.0, 0.0, 0.05)));
  EXPECT_TRUE(added.T_map_base.isApprox(added.T_map_base_odom));
  EXPECT_TRUE(store.CorrectedPose(5).isApprox(T_map_odom * added.T_map_base_odom, 1e-12));
  store.Clear();
  EXPECT_TRUE(store.T_map_odom().isApprox(Eigen::Isometry3d::Identity()));
  store.AddFrame(9.0, Pose(1.0, 0.0, 0.0, 0.0, 0.0, 0.0));
  EXPECT_TRUE(store.CorrectedPose(0).isApprox(Pose(1.0, 0.0, 0.0, 0.0, 0.0, 0.0)));
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
