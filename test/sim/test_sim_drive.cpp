// Synthetic drives: determinism, the plain-IPM error regime of the default scenario, the
// odometry model, stamps, and the road model's geometry.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "ipm_road_mapper/core/geometry/rigid_transform.h"
#include "ipm_road_mapper/sim/drive_simulator.h"
#include "ipm_road_mapper/sim/ipm_check.h"
#include "ipm_road_mapper/sim/sim_random.h"

namespace ipm_road_mapper {
namespace sim {
namespace {

const std::string kSource = IRM_SOURCE_DIR;

ClassTable Classes() { return ClassTable::LoadFile(kSource + "/config/classes.yaml"); }

ScenarioOptions Scenario(const std::string& name) {
  return LoadScenarioFile(kSource + "/config/scenarios/" + name + ".yaml", Classes());
}

std::string SerializedGroundTruth(const GroundTruth& gt, const std::string& tag) {
  const std::string path = ::testing::TempDir() + "/sim_gt_" + tag + ".json";
  SaveGroundTruthJson(gt, path);
  std::ifstream in(path, std::ios::binary);
  std::stringstream bytes;
  bytes << in.rdbuf();
  std::remove(path.c_str());
  return bytes.str();
}

TEST(SimDrive, SameSeedGivesIdenticalOutputDifferentSeedDifferentOdometry) {
  const ScenarioOptions scenario = Scenario("public_road");
  const ClassTable classes = Classes();
  DriveSimulator a(scenario, classes, 42, 60), b(scenario, classes, 42, 60),
      c(scenario, classes, 43, 60);
  for (int k : {0, 31, 59}) {
    const SimFrame fa = a.RenderFrame(k), fb = b.RenderFrame(k);
    c.RenderFrame(k);
    EXPECT_EQ(cv::norm(fa.mask, fb.mask, cv::NORM_INF), 0.0) << "frame " << k;
    EXPECT_EQ(cv::norm(fa.image, fb.image, cv::NORM_INF), 0.0) << "frame " << k;
  }
  const std::string json_a = SerializedGroundTruth(a.ground_truth(), "a");
  EXPECT_GT(json_a.size(), 1000u);
  EXPECT_EQ(json_a, SerializedGroundTruth(b.ground_truth(), "b"));
  EXPECT_NE(json_a, SerializedGroundTruth(c.ground_truth(), "c"));
  ASSERT_EQ(a.odometry().size(), c.odometry().size());
  double max_difference = 0.0;
  for (std::size_t j = 0; j < a.odometry().size(); ++j) {
    EXPECT_EQ(a.odometry()[j].stamp_ns, b.odometry()[j].stamp_ns);
    EXPECT_TRUE(a.odometry()[j].T_map_base.isApprox(b.odometry()[j].T_map_base, 0.0));
    max_difference = std::max(max_difference, (a.odometry()[j].T_map_base.translation() -
                                               c.odometry()[j].T_map_base.translation())
                                                  .norm());
  }
  EXPECT_GT(max_difference, 0.01);
}

TEST(SimDrive, DefaultScenarioPutsPlainIpmInThePapersErrorRegime) {
  const ScenarioOptions scenario = Scenario("public_road");
  for (std::uint32_t seed : {1u, 2u, 3u}) {
    const DriveSimulator drive(scenario, Classes(), seed);
    const PlainIpmError error =
        ComputePlainIpmError(drive.ground_truth(), scenario.ipm_check.max_distance_m);
    EXPECT_EQ(error.markings, static_cast<int>(drive.world().markings().size()));
    EXPECT_GE(error.mean_m, 0.35) << "seed " << seed;
    EXPECT_LE(error.mean_m, 0.9) << "seed " << seed;
  }
}

TEST(SimDrive, PlainIpmIsExactWithoutAnyErrorSource) {
  // Flat road, true extrinsic, perfect odometry, rigid body: the check must give zero, so
  // the check, the renderer's geometry and the extrinsic conventions agree.
  ScenarioOptions scenario = Scenario("public_road");
  scenario.road.surface = SurfaceOptions();
  scenario.rough_extrinsic = RoughExtrinsicOptions();
  scenario.odometry.xy_std_m = scenario.odometry.yaw_std_deg = 0.0;
  scenario.odometry.jitter_xy_m = scenario.odometry.jitter_yaw_deg = 0.0;
  scenario.vehicle.pitch_amplitude_deg = scenario.vehicle.roll_amplitude_deg = 0.0;
  scenario.vehicle.heave_amplitude_m = 0.0;
  const DriveSimulator drive(scenario, Classes(), 1);
  const PlainIpmError error = ComputePlainIpmError(drive.ground_truth(), 25.0);
  EXPECT_GT(error.markings, 10);
  EXPECT_LT(error.max_m, 1e-6);
}

TEST(SimDrive, StampsAndOdometryRates) {
  const ScenarioOptions scenario = Scenario("public_road");
  const DriveSimulator drive(scenario, Classes(), 1, 100);
  ASSERT_EQ(drive.num_frames(), 100);
  EXPECT_EQ(drive.FrameStampNs(0), 1000000000000LL);
  EXPECT_EQ(drive.FrameStampNs(1) - drive.FrameStampNs(0), 50000000LL);
  const auto& odometry = drive.odometry();
  ASSERT_GT(odometry.size(), 2u);
  EXPECT_LT(odometry.front().stamp_ns, drive.FrameStampNs(0));
  EXPECT_GT(odometry.back().stamp_ns, drive.FrameStampNs(99));
  EXPECT_EQ(odometry[1].stamp_ns - odometry[0].stamp_ns, 20000000LL);
  for (const auto& sample : odometry) {
    for (int k = 0; k < drive.num_frames(); ++k) EXPECT_NE(sample.stamp_ns, drive.FrameStampNs(k));
  }
  // The body-frame speed of the odometry track is about the scenario speed.
  EXPECT_NEAR(odometry[10].linear_velocity_base.x(), scenario.vehicle.speed_mps, 1.0);
}

TEST(SimDrive, OdometryErrorHasTheConfiguredSpreadAndIsSmooth) {
  OdometryOptions options;
  options.xy_std_m = 0.3;
  options.yaw_std_deg = 0.4;
  options.correlation_time_s = 2.0;
  options.jitter_xy_m = options.jitter_yaw_deg = 0.0;
  OdometryErrorModel model(options, 5);
  const int n = 200000;
  const double dt = 0.02;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero(), sum2 = Eigen::Vector3d::Zero();
  Eigen::Vector3d previous = model.Next(dt);
  double max_step = 0.0;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d e = model.Next(dt);
    sum += e;
    sum2 += e.cwiseProduct(e);
    max_step = std::max(max_step, (e - previous).head<2>().norm());
    previous = e;
  }
  const Eigen::Vector3d mean = sum / n;
  const Eigen::Vector3d std = (sum2 / n - mean.cwiseProduct(mean)).cwiseSqrt();
  EXPECT_NEAR(std.x(), 0.3, 0.03);
  EXPECT_NEAR(std.y(), 0.3, 0.03);
  EXPECT_NEAR(std.z(), 0.4 * M_PI / 180.0, 0.04 * M_PI / 180.0);
  // Per 20 ms step the error moves ~ sigma sqrt(2 dt / tau) = 0.03 m, never jumps.
  EXPECT_LT(max_step, 0.3);
}

TEST(SimDrive, RandomStreamsAreDeterministicAndIndependent) {
  SimRandom a = SimRandom::ForStream(1, RandomStream::kOdometry, 3);
  SimRandom b = SimRandom::ForStream(1, RandomStream::kOdometry, 3);
  SimRandom c = SimRandom::ForStream(1, RandomStream::kSegmentation, 3);
  const double x = a.Normal();
  EXPECT_EQ(x, b.Normal());
  EXPECT_NE(x, c.Normal());
}

TEST(SimRoad, CenterlineIsContinuousAndArcsHaveTheirRadius) {
  const RoadModel road(Scenario("public_road").road);
  EXPECT_NEAR(road.length(), 60 + 200 * 20 * M_PI / 180 + 40 + 150 * 25 * M_PI / 180 + 70, 1e-9);
  for (double s = -5.0; s < road.length() + 5.0; s += 0.05) {
    const CenterlinePoint a = road.Centerline(s), b = road.Centerline(s + 0.01);
    EXPECT_NEAR((b.xy - a.xy).norm(), 0.01, 1e-6) << "s = " << s;
    // Heading continuous (it turns by at most 0.01 m / R_min, also across piece boundaries).
    EXPECT_LE(std::abs(b.heading - a.heading), 0.01 / 150.0 + 1e-12) << "s = " << s;
  }
  EXPECT_NEAR(road.Centerline(100.0).curvature, 1.0 / 200.0, 1e-12);
  EXPECT_NEAR(road.Centerline(200.0).curvature, -1.0 / 150.0, 1e-12);
  EXPECT_NEAR(road.Centerline(road.length()).heading, (20.0 - 25.0) * M_PI / 180.0, 1e-9);
}

TEST(SimRoad, SurfaceIsNotPlanarAndLocateInvertsSurfacePoint) {
  const RoadModel road(Scenario("hilly").road);
  double min_z = 1e9, max_z = -1e9;
  for (double s = 0.0; s < road.length(); s += 1.0) {
    for (double l : {-4.0, 0.0, 3.0}) {
      const Eigen::Vector3d p = road.SurfacePoint(s, l);
      const Eigen::Vector2d sl = road.Locate(p.head<2>(), s + 3.0);
      EXPECT_NEAR(sl.x(), s, 1e-6);
      EXPECT_NEAR(sl.y(), l, 1e-6);
      min_z = std::min(min_z, p.z());
      max_z = std::max(max_z, p.z());
      // Height is C1: the slope changes little over 1 cm (a kink between grades of 6 % and
      // -4 % would change it by 0.1; the steepest curvature here, the bumps', gives 1e-3).
      const double g0 = (road.Height(s + 0.01, l) - road.Height(s, l)) / 0.01;
      const double g1 = (road.Height(s + 0.02, l) - road.Height(s + 0.01, l)) / 0.01;
      EXPECT_LT(std::abs(g1 - g0), 3e-3);
    }
  }
  EXPECT_GT(max_z - min_z, 2.0);  // grades up to 6 %
  EXPECT_NEAR(road.Height(50.0, 1.0) - road.Height(50.0, 0.0), road.cross_slope(), 1e-12);
}

TEST(SimRoad, VehicleRestsOnTheSurfaceAndFollowsTheRoad) {
  ScenarioOptions scenario = Scenario("hilly");
  scenario.vehicle.heave_amplitude_m = 0.0;
  const RoadModel road(scenario.road);
  const VehicleTrajectory trajectory(road, scenario.vehicle, 1);
  for (double t = 0.0; t < 10.0; t += 0.37) {
    const Eigen::Isometry3d T = trajectory.Pose(t);
    const Eigen::Vector3d p = T.translation();
    const Eigen::Vector2d sl = road.Locate(p.head<2>(), trajectory.S(t));
    EXPECT_NEAR(p.z(), road.Height(sl.x(), sl.y()), 1e-9);
    EXPECT_NEAR(sl.y(), trajectory.L(t), 1e-6);
    // x axis along the road (within the wander's few tenths of a degree and the grade).
    const Eigen::Vector2d forward = T.linear().col(0).head<2>().normalized();
    EXPECT_GT(forward.dot(road.Centerline(sl.x()).Tangent()), std::cos(2.0 * M_PI / 180.0));
  }
}

// A crown makes the road a roof across: each side a plane falling from the ridge, the
// cross slope on top. What the mapper faces on a real carriageway (docs/synthetic_drives.md,
// "The crown"), which the planar cross slope never showed it.
TEST(SimRoad, CrownIsARoofAcrossTheRoadWithItsRidgeWhereConfigured) {
  RoadOptions options = Scenario("public_road").road;
  options.surface.cross_slope_pct = 1.0;
  options.surface.crown_pct = 2.0;
  options.surface.crown_offset_m = 1.75;
  const RoadModel road(options);
  const double s = 40.0;
  // Right of the ridge: rising toward it at cross + crown; left of it: cross - crown.
  EXPECT_NEAR(road.Height(s, 1.0) - road.Height(s, 0.0), 0.03, 1e-12);
  EXPECT_NEAR(road.Height(s, 3.0) - road.Height(s, 2.0), -0.01, 1e-12);
  // The ridge is the highest point of a cross-section without cross slope.
  options.surface.cross_slope_pct = 0.0;
  const RoadModel roof(options);
  for (double l : {-5.25, -1.75, 0.0, 1.7, 1.8, 5.25}) {
    EXPECT_LT(roof.Height(s, l), roof.Height(s, 1.75)) << l;
  }
  EXPECT_NEAR(roof.Height(s, 5.25) - roof.Height(s, 1.75), -0.07, 1e-12);
  EXPECT_EQ(roof.CrossHeight(1.75), 0.0);
  // Without a crown the cross-section is the plane it always was.
  options.surface.crown_pct = 0.0;
  options.surface.cross_slope_pct = 2.0;
  const RoadModel plane(options);
  EXPECT_NEAR(plane.Height(s, 3.0) - plane.Height(s, -3.0), 0.12, 1e-12);
}

TEST(SimRoad, VehicleOnOneSideOfTheRidgeRollsWithThatSide) {
  ScenarioOptions scenario = Scenario("public_road");
  scenario.road.surface.cross_slope_pct = 0.0;
  scenario.road.surface.crown_pct = 2.0;
  scenario.road.surface.crown_offset_m = 1.75;  // the left line of the vehicle's lane 1
  scenario.vehicle.roll_amplitude_deg = 0.0;
  scenario.vehicle.wander_amplitude_m = 0.0;
  const RoadModel road(scenario.road);
  const VehicleTrajectory trajectory(road, scenario.vehicle, 1);
  for (double t : {0.5, 1.7, 2.9}) {
    const Eigen::Isometry3d T = trajectory.Pose(t);
    const double roll = RpyFromRotation(T.linear()).x();
    EXPECT_NEAR(roll, std::atan(0.02), 1e-3) << t;  // left side up, toward the ridge
  }
}

TEST(SimRoad, RidgeHidesTheRoadBeyondItFromALowCamera) {
  RoadOptions options = Scenario("public_road").road;
  options.surface = SurfaceOptions();
  options.surface.crown_pct = 10.0;  // a steep roof: 0.5 m over 5 m
  options.surface.crown_offset_m = 0.0;
  const RoadModel road(options);
  const double s_cam = 20.0, l_cam = -5.0;
  const Eigen::Vector3d camera = road.SurfacePoint(s_cam, l_cam) + Eigen::Vector3d(0, 0, 0.2);
  const SightProfile sight(road, camera, s_cam, 40.0);
  // Across the ridge, on the far side's surface: hidden; the near side: in sight; the same
  // point lifted above the ridge's sight line: in sight.
  EXPECT_FALSE(sight.Visible(s_cam + 6.0, 5.0, road.Height(s_cam + 6.0, 5.0)));
  EXPECT_TRUE(sight.Visible(s_cam + 6.0, -4.0, road.Height(s_cam + 6.0, -4.0)));
  EXPECT_TRUE(sight.Visible(s_cam + 6.0, 5.0, road.Height(s_cam + 6.0, 5.0) + 1.5));
  // A planar road with the same cross slope on both sides hides nothing.
  options.surface.crown_pct = 0.0;
  options.surface.cross_slope_pct = 10.0;
  const RoadModel plane(options);
  const Eigen::Vector3d camera2 = plane.SurfacePoint(s_cam, l_cam) + Eigen::Vector3d(0, 0, 0.2);
  const SightProfile sight2(plane, camera2, s_cam, 40.0);
  EXPECT_TRUE(sight2.Visible(s_cam + 6.0, 5.0, plane.Height(s_cam + 6.0, 5.0)));
}

}  // namespace
}  // namespace sim
}  // namespace ipm_road_mapper
