// The evaluator on hostile maps: a lane that reaches 1e6 m away (inside the readers'
// coordinate bound) must be refused by the lane sample budget in well under a second, not
// sampled 10^7 times (which cost 14 s and 1.8 GB); markings piled on each other must not
// collect N * M candidate pairs, and many spread-out markings must match quickly.
#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <vector>

#include "ipm_road_mapper/eval/evaluation.h"

namespace ipm_road_mapper {
namespace {

GroundTruth TinyGroundTruth() {
  GroundTruth gt;
  gt.scenario = "tiny";
  gt.camera = {640, 480, 500.0, 500.0, 320.0, 240.0, {0, 0, 0, 0, 0}};
  GroundTruthLane lane;
  lane.id = 1;
  for (int k = 0; k <= 200; ++k) lane.points_map.emplace_back(0.1 * k, 0.0, 0.0);
  gt.lanes.push_back(lane);
  return gt;
}

// A map with one straight lane of 6 control points, the fourth (on the curve) at `far_x_m`.
VectorMap MapWithLaneTo(double far_x_m) {
  VectorMap map;
  MapLane lane;
  lane.id = 1;
  for (int k = 0; k < 3; ++k) lane.control_points_map.emplace_back(4.0 * k, 0.0, 0.0);
  for (double x : {far_x_m, far_x_m + 4.0, far_x_m + 8.0}) {
    lane.control_points_map.emplace_back(x, 0.0, 0.0);
  }
  map.lanes.push_back(lane);
  return map;
}

TEST(EvaluationLimits, AFarControlPointIsRefusedByTheSampleBudget) {
  const auto start = std::chrono::steady_clock::now();
  try {
    EvaluateMap(MapWithLaneTo(1e6), TinyGroundTruth(), EvaluationOptions());
    ADD_FAILURE() << "a lane reaching 1e6 m was sampled";
  } catch (const MapFormatError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("map lanes[0]"), std::string::npos) << what;
    EXPECT_NE(what.find("beyond the evaluator's budget of 1e+06 samples"), std::string::npos)
        << what;
  }
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 1.0);
}

TEST(EvaluationLimits, AnOrdinaryLaneIsWithinTheBudget) {
  const Metrics metrics = EvaluateMap(MapWithLaneTo(20.0), TinyGroundTruth(), EvaluationOptions());
  EXPECT_EQ(metrics.lanes.map_total, 1);
  EXPECT_GT(metrics.lanes.error_m.count, 100);
}

// `count` square markings of class 10 centered every `spacing_m` along x (0: all at x = 0).
std::vector<MapMarking> MarkingsAlongX(int count, double spacing_m) {
  std::vector<MapMarking> markings(count);
  for (int k = 0; k < count; ++k) {
    const double x = spacing_m * k;
    markings[k].id = k + 1;
    markings[k].class_id = 10;
    markings[k].corners_map = {Eigen::Vector3d(x - 0.5, -0.5, 0), Eigen::Vector3d(x + 0.5, -0.5, 0),
                               Eigen::Vector3d(x + 0.5, 0.5, 0), Eigen::Vector3d(x - 0.5, 0.5, 0)};
  }
  return markings;
}

// A ground truth with the same markings as MarkingsAlongX, seen.
GroundTruth GroundTruthWithMarkings(int count, double spacing_m) {
  GroundTruth gt = TinyGroundTruth();
  for (const MapMarking& m : MarkingsAlongX(count, spacing_m)) {
    GroundTruthMarking g;
    g.id = static_cast<int>(m.id);
    g.class_id = m.class_id;
    g.corners_map = m.corners_map;
    g.center_map = m.Center();
    g.visible_frames = 1;
    gt.markings.push_back(g);
  }
  return gt;
}

TEST(EvaluationLimits, ManySpreadMarkingsMatchQuickly) {
  VectorMap map;
  map.markings = MarkingsAlongX(50000, 5.0);
  const auto start = std::chrono::steady_clock::now();
  const MarkingMetrics metrics =
      EvaluateMarkings(map, GroundTruthWithMarkings(50000, 5.0), EvaluationOptions());
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 1.0);
  EXPECT_EQ(metrics.matched, 50000);
  EXPECT_EQ(metrics.duplicates, 0);
}

TEST(EvaluationLimits, MarkingsPiledOnEachOtherAreRefused) {
  VectorMap map;
  map.markings = MarkingsAlongX(4000, 0.0);  // 4000 x 4000 pairs within the gate
  const auto start = std::chrono::steady_clock::now();
  try {
    EvaluateMarkings(map, GroundTruthWithMarkings(4000, 0.0), EvaluationOptions());
    ADD_FAILURE() << "16e6 candidate pairs were collected";
  } catch (const MapFormatError& e) {
    EXPECT_NE(std::string(e.what()).find("map markings: more than 10000000"), std::string::npos)
        << e.what();
  }
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 2.0);
}

}  // namespace
}  // namespace ipm_road_mapper
