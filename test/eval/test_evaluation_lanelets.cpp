// The lanelet metrics (EvaluateLanelets): the map's lanelets against the GT's, both found by
// the Lanelet2 export's rule, compared by centerline length; a lane whose line is broken in
// two is two lanelets, a missing line loses its lanes, lines 1 m off are no match.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "ipm_road_mapper/eval/evaluation.h"

namespace ipm_road_mapper {
namespace {

// Three GT lines at y -1.75, 1.75, 5.25 along x 0-100 m (points every 0.1 m), the drive along
// y = 0: two lanes.
GroundTruth ThreeLines() {
  GroundTruth gt;
  int id = 0;
  for (double y : {-1.75, 1.75, 5.25}) {
    GroundTruthLane lane;
    lane.id = ++id;
    lane.class_name = "lane_white_solid";
    for (int k = 0; k <= 1000; ++k) lane.points_map.emplace_back(0.1 * k, y, 0.0);
    gt.lanes.push_back(lane);
  }
  for (int k = 0; k <= 50; ++k) {
    GroundTruthFrame frame;
    frame.stamp = 0.1 * k;
    frame.T_map_base_true.translation() = Eigen::Vector3d(2.0 * k, 0.0, 0.0);
    gt.frames.push_back(frame);
  }
  return gt;
}

// A map lane along y from x0 to x1 (control points every 5 m; a Catmull-Rom curve runs from
// its second control point to its last but one).
MapLane Line(std::uint64_t id, double y, double x0, double x1) {
  MapLane lane;
  lane.id = id;
  lane.class_name = "lane_white_solid";
  for (double x = x0 - 5.0; x <= x1 + 5.0 + 1e-9; x += 5.0) {
    lane.control_points_map.emplace_back(x, y, 0.0);
  }
  return lane;
}

VectorMap MapOf(std::vector<MapLane> lanes) {
  VectorMap map;
  map.lanes = std::move(lanes);
  for (int k = 0; k <= 50; ++k) {
    StampedPose pose;
    pose.stamp = 0.1 * k;
    pose.T_map_base.translation() = Eigen::Vector3d(2.0 * k, 0.0, 0.0);
    map.trajectory.push_back(pose);
  }
  return map;
}

const EvaluationOptions kOptions;

TEST(EvaluationLanelets, TheGroundTruthsLinesMappedAreItsLanelets) {
  const LaneletMetrics m = EvaluateLanelets(
      MapOf({Line(1, -1.75, 0, 100), Line(2, 1.75, 0, 100), Line(3, 5.25, 0, 100)}), ThreeLines(),
      kOptions);
  EXPECT_EQ(m.gt_total, 2);
  EXPECT_EQ(m.map_total, 2);
  EXPECT_NEAR(m.gt_length_m, 200.0, 2.0);  // two lanes of 100 m
  EXPECT_GT(m.recall, 0.97);
  EXPECT_GT(m.precision, 0.95);
  EXPECT_DOUBLE_EQ(m.lanelets_per_covered_gt_lanelet, 1.0);
}

TEST(EvaluationLanelets, ALineInTwoPiecesMakesEachLaneTwoLanelets) {
  const LaneletMetrics m = EvaluateLanelets(MapOf({Line(1, -1.75, 0, 100), Line(2, 1.75, 0, 50),
                                                   Line(4, 1.75, 55, 100), Line(3, 5.25, 0, 100)}),
                                            ThreeLines(), kOptions);
  EXPECT_EQ(m.map_total, 4);
  EXPECT_NEAR(m.recall, 0.95, 0.03);  // the 5 m gap is no lane
  EXPECT_DOUBLE_EQ(m.lanelets_per_covered_gt_lanelet, 2.0);
}

TEST(EvaluationLanelets, AMissingLineLosesItsLanesAndLinesOffByAMetreMatchNothing) {
  const LaneletMetrics missing = EvaluateLanelets(
      MapOf({Line(1, -1.75, 0, 100), Line(2, 1.75, 0, 100)}), ThreeLines(), kOptions);
  EXPECT_EQ(missing.map_total, 1);
  EXPECT_NEAR(missing.recall, 0.5, 0.06);
  EXPECT_GT(missing.precision, 0.95);

  const LaneletMetrics shifted = EvaluateLanelets(
      MapOf({Line(1, -0.75, 0, 100), Line(2, 2.75, 0, 100), Line(3, 6.25, 0, 100)}), ThreeLines(),
      kOptions);
  EXPECT_EQ(shifted.map_total, 2);
  EXPECT_DOUBLE_EQ(shifted.recall, 0.0);
  EXPECT_DOUBLE_EQ(shifted.precision, 0.0);
  EXPECT_TRUE(std::isnan(shifted.lanelets_per_covered_gt_lanelet));
}

TEST(EvaluationLanelets, AnEmptyMapHasNoRecallAndNoPrecision) {
  const LaneletMetrics m = EvaluateLanelets(MapOf({}), ThreeLines(), kOptions);
  EXPECT_EQ(m.map_total, 0);
  EXPECT_DOUBLE_EQ(m.recall, 0.0);
  EXPECT_TRUE(std::isnan(m.precision));
  EXPECT_TRUE(std::isnan(m.lanelets_per_covered_gt_lanelet));
}

}  // namespace
}  // namespace ipm_road_mapper
