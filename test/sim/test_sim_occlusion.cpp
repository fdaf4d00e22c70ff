// The urban-scenario pieces of the simulator: vehicles ahead that hide the road
// (occluders), split instances, and the urban scenario's plain-IPM regime.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <set>
#include <string>

#include "ipm_road_mapper/sim/drive_simulator.h"
#include "ipm_road_mapper/sim/instance_split.h"
#include "ipm_road_mapper/sim/ipm_check.h"
#include "ipm_road_mapper/sim/occluder.h"

namespace ipm_road_mapper {
namespace sim {
namespace {

const std::string kSource = IRM_SOURCE_DIR;

ClassTable Classes() { return ClassTable::LoadFile(kSource + "/config/classes.yaml"); }

ScenarioOptions Scenario(const std::string& name) {
  return LoadScenarioFile(kSource + "/config/scenarios/" + name + ".yaml", Classes());
}

ScenarioOptions Load(const std::string& yaml) {
  return LoadScenario(OptionsReader(YAML::Load(yaml), ""), Classes());
}

std::string ErrorOf(const std::string& yaml) {
  try {
    Load(yaml);
  } catch (const OptionsError& e) {
    return e.what();
  }
  return "";
}

const std::string kRoad = "name: t\nroad:\n  segments: [{type: straight, length_m: 100}]\n";

TEST(SimInstanceSplit, CutsAnInstanceThroughItsCentroidAndLeavesOthersAlone) {
  cv::Mat mask = cv::Mat::zeros(20, 30, CV_16UC1);
  mask(cv::Rect(4, 5, 10, 6)).setTo(10001);  // 60 px, centroid column 8.5
  mask(cv::Rect(20, 5, 4, 4)).setTo(10002);
  EXPECT_EQ(SplitInstance(10001, 10007, Eigen::Vector2d(1.0, 0.0), &mask), 30);
  EXPECT_EQ(cv::countNonZero(mask == 10001), 30);
  EXPECT_EQ(cv::countNonZero(mask == 10007), 30);
  EXPECT_EQ(cv::countNonZero(mask == 10002), 16);
  for (int r = 5; r < 11; ++r) {
    EXPECT_EQ(mask.at<std::uint16_t>(r, 4), 10001);   // left of the centroid: kept
    EXPECT_EQ(mask.at<std::uint16_t>(r, 13), 10007);  // right: relabelled
  }
  EXPECT_EQ(SplitInstance(10005, 10008, Eigen::Vector2d(0.0, 1.0), &mask), 0);  // absent
}

TEST(SimOccluder, BoxFollowsTheGapAndExistsOnlyInItsStretch) {
  const ScenarioOptions scenario =
      Load(kRoad +
           "occluders:\n  - {lane: 1, gap_m: 10, gap_amplitude_m: 2, gap_period_s: 4,"
           " start_s_m: 20, end_s_m: 60}\n");
  ASSERT_EQ(scenario.occluders.size(), 1u);
  const OccluderOptions& o = scenario.occluders[0];
  EXPECT_DOUBLE_EQ(o.length_m, 4.5);
  const RoadModel road(scenario.road);
  EXPECT_NEAR(OccluderRearS(o, 15.0, 0.0), 25.0, 1e-12);
  EXPECT_NEAR(OccluderRearS(o, 15.0, 1.0), 27.0, 1e-12);   // a quarter period: + amplitude
  EXPECT_TRUE(OccluderFaces(road, o, 5.0, 0.0).empty());   // rear at 15 m < start
  EXPECT_TRUE(OccluderFaces(road, o, 55.0, 0.0).empty());  // rear at 65 m > end
  const auto faces = OccluderFaces(road, o, 15.0, 0.0);
  ASSERT_EQ(faces.size(), 6u);
  const double l = road.LaneCenterOffset(1);
  const Eigen::Vector3d rear_right = road.SurfacePoint(25.0, l - 0.9);
  EXPECT_LT((faces[0][0] - rear_right).norm(), 1e-9);  // the footprint lies on the surface
  EXPECT_LT((faces[1][2] - road.SurfacePoint(29.5, l + 0.9) - Eigen::Vector3d(0, 0, 1.5)).norm(),
            1e-9);
}

TEST(SimOccluder, ScenarioKeysAreValidated) {
  EXPECT_NE(ErrorOf(kRoad + "occluders: [{lane: 1, gapm: 3}]").find("occluders[0].gapm"),
            std::string::npos);
  EXPECT_NE(ErrorOf(kRoad + "occluders: [{gap_m: 5, gap_amplitude_m: 5}]")
                .find("occluders[0].gap_amplitude_m"),
            std::string::npos);
  EXPECT_NE(ErrorOf(kRoad + "occluders: [{lane: 7}]").find("occluders[0].lane"), std::string::npos);
  EXPECT_NE(ErrorOf(kRoad + "segmentation: {split_instance_prob: 1.5}")
                .find("segmentation.split_instance_prob"),
            std::string::npos);
  EXPECT_EQ(Load(kRoad + "occluders: [{lane: 0}]").occluders[0].end_s_m, 100.0);
}

TEST(SimOccluder, VehicleAheadHidesTheRoadBehindItAndNothingElse) {
  ScenarioOptions scenario = Scenario("public_road");
  const ClassTable classes = Classes();
  RenderSettings exact;
  exact.segmentation_noise = false;
  exact.image = false;
  DriveSimulator open_road(scenario, classes, 1, 40);
  OccluderOptions vehicle;
  vehicle.lane = scenario.vehicle.lane;
  vehicle.gap_m = 8.0;
  scenario.occluders = {vehicle};
  scenario.occluders[0].end_s_m = 1000.0;
  DriveSimulator occluded(scenario, classes, 1, 40);
  for (int k : {0, 20, 39}) {
    const SimFrame a = open_road.RenderFrame(k, exact), b = occluded.RenderFrame(k, exact);
    // Every pixel left is as it was without the vehicle; some paint is hidden.
    const cv::Mat changed = a.mask != b.mask;
    EXPECT_EQ(cv::countNonZero(changed & (b.mask != 0)), 0) << "frame " << k;
    EXPECT_GT(cv::countNonZero(changed), 100) << "frame " << k;
    // The road nearer than the vehicle is untouched: no change below its rear's image row.
    const Eigen::Isometry3d T_cam_map = (b.T_map_base_true * occluded.T_base_cam_true()).inverse();
    const RoadModel& road = occluded.world().road();
    const double s_cam =
        road.Locate(T_cam_map.inverse().translation().head<2>(), 6.5 + 0.5 * k).x();
    const auto faces = OccluderFaces(road, scenario.occluders[0], s_cam, k / 20.0);
    ASSERT_EQ(faces.size(), 6u);
    Eigen::Vector2d rear_uv;
    ASSERT_TRUE(occluded.camera().Project<double>(T_cam_map * faces[0][0], &rear_uv));
    const int row = static_cast<int>(std::ceil(rear_uv.y())) + 2;
    EXPECT_EQ(cv::countNonZero(changed.rowRange(row, changed.rows)), 0) << "frame " << k;
  }
}

// segmentation.occluder_class_id: the same vehicle, drawn as its own instance of that class
// (as a panoptic network labels vehicles) instead of background; everything else unchanged.
TEST(SimOccluder, LabelledVehicleIsItsOwnInstanceWhereTheBackgroundVehicleIsZero) {
  ScenarioOptions scenario = Scenario("public_road");
  RenderSettings exact;
  exact.segmentation_noise = false;
  exact.image = false;
  OccluderOptions vehicle;
  vehicle.lane = scenario.vehicle.lane;
  vehicle.gap_m = 8.0;
  vehicle.end_s_m = 1000.0;
  scenario.occluders = {vehicle};
  DriveSimulator background(scenario, Classes(), 1, 30);
  scenario.segmentation.occluder_class_id = 30;
  DriveSimulator labelled(scenario, Classes(), 1, 30);
  const SimFrame a = background.RenderFrame(20, exact), b = labelled.RenderFrame(20, exact);
  const cv::Mat vehicle_pixels = b.mask == 30 * kInstanceIdFactor + 1;
  EXPECT_GT(cv::countNonZero(vehicle_pixels), 500);
  // Where the labelled vehicle is, the background one left 0; elsewhere both masks agree.
  EXPECT_EQ(cv::countNonZero(vehicle_pixels & (a.mask != 0)), 0);
  EXPECT_EQ(cv::countNonZero((a.mask != b.mask) & ~vehicle_pixels), 0);
  // The vehicle is no mapped element: not among the rendered instances.
  for (const RenderedInstance& instance : b.instances) {
    EXPECT_NE(instance.value / kInstanceIdFactor, 30);
  }
  EXPECT_NE(ErrorOf(kRoad + "segmentation: {occluder_class_id: 66}")
                .find("segmentation.occluder_class_id"),
            std::string::npos);
}

// segmentation.mask_rasterizer: pixel_centers labels what cv::fillPoly labels less the pixels
// whose centers are outside (about half a pixel around every instance).
TEST(SimMask, PixelCenterRasterizerLabelsASubsetOfTheDefaultOne) {
  ScenarioOptions scenario = Scenario("public_road");
  RenderSettings exact;
  exact.segmentation_noise = false;
  exact.image = false;
  DriveSimulator fill_poly(scenario, Classes(), 1, 30);
  scenario.segmentation.mask_rasterizer = FillRule::kPixelCenters;
  DriveSimulator centers(scenario, Classes(), 1, 30);
  const SimFrame a = fill_poly.RenderFrame(20, exact), b = centers.RenderFrame(20, exact);
  const int labelled_a = cv::countNonZero(a.mask), labelled_b = cv::countNonZero(b.mask);
  EXPECT_GT(labelled_b, 10000);
  // Every pixel the center rule labels is labelled under cv::fillPoly (but a few whose
  // centers lie within cv::fillPoly's 1/16 px rounding of an edge), with the same instance
  // but where two instances touch (the later one's wider rim covers the earlier one there).
  EXPECT_LT(cv::countNonZero((b.mask != 0) & (a.mask == 0)), labelled_b / 1000);
  EXPECT_LT(cv::countNonZero((b.mask != 0) & (a.mask != b.mask)), labelled_b / 1000);
  // The difference is a rim: a few percent of the paint, not nothing.
  EXPECT_GT(labelled_a - labelled_b, labelled_b / 50);
  EXPECT_LT(labelled_a - labelled_b, labelled_b / 2);
  EXPECT_EQ(Load(kRoad).segmentation.mask_rasterizer, FillRule::kOpenCvFillPoly);
  EXPECT_EQ(
      Load(kRoad + "segmentation: {mask_rasterizer: pixel_centers}").segmentation.mask_rasterizer,
      FillRule::kPixelCenters);
  EXPECT_NE(ErrorOf(kRoad + "segmentation: {mask_rasterizer: exact}")
                .find("segmentation.mask_rasterizer"),
            std::string::npos);
}

TEST(SimSplit, SplitPartsAreInstancesOfTheSameElementCountedOnceAsVisible) {
  ScenarioOptions scenario = Scenario("public_road");
  scenario.segmentation.split_instance_prob = 1.0;
  scenario.segmentation.spurious_blobs_per_frame = 0.0;
  DriveSimulator drive(scenario, Classes(), 1, 30);
  const SimFrame frame = drive.RenderFrame(10);
  std::set<int> values;
  std::map<std::pair<int, int>, int> parts;
  for (const RenderedInstance& instance : frame.instances) {
    EXPECT_TRUE(values.insert(instance.value).second) << "duplicate value " << instance.value;
    EXPECT_LT(instance.value % kInstanceIdFactor, kInstanceIdFactor);
    EXPECT_EQ(cv::countNonZero(frame.mask == instance.value), instance.pixels);
    ++parts[{static_cast<int>(instance.source), instance.gt_id}];
  }
  int split = 0;
  for (const auto& [element, count] : parts) {
    EXPECT_LE(count, 2);
    split += count == 2;
  }
  EXPECT_GE(split, 3);
  for (const GroundTruthMarking& m : drive.ground_truth().markings) {
    EXPECT_LE(m.visible_frames, 1);
  }
}

TEST(SimUrban, PortraitCameraOfTheRealDriveAndPlainIpmInThePapersRegime) {
  const ScenarioOptions scenario = Scenario("urban");
  EXPECT_EQ(scenario.camera.intrinsics.width, 775);
  EXPECT_EQ(scenario.camera.intrinsics.height, 1024);
  EXPECT_FALSE(scenario.occluders.empty());
  EXPECT_GT(scenario.segmentation.split_instance_prob, 0.0);
  for (std::uint32_t seed : {1u, 2u}) {
    const DriveSimulator drive(scenario, Classes(), seed);
    const PlainIpmError error =
        ComputePlainIpmError(drive.ground_truth(), scenario.ipm_check.max_distance_m);
    EXPECT_GE(error.mean_m, 0.35) << "seed " << seed;
    EXPECT_LE(error.mean_m, 0.9) << "seed " << seed;
  }
}

}  // namespace
}  // namespace sim
}  // namespace ipm_road_mapper
