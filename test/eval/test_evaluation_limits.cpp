// The evaluator on hostile maps: a lane that reaches 1e6 m away (inside the readers'
// coordinate bound) must be refused by the lane sample budget in well under a second, not
// sampled 10^7 times (which cost 14 s and 1.8 GB).
#include <gtest/gtest.h>

#include <chrono>
#include <string>

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

}  // namespace
}  // namespace ipm_road_mapper
