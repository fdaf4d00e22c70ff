// Lane topology (lane_topology.h) and its map-file round trip: a line that goes on in
// another class and a fork's branch are linked; a double line's halves and lanes far apart
// are not; a file whose lane names itself is refused.
#include <gtest/gtest.h>

#include <cmath>

#include "ipm_road_mapper/core/map/vector_map.h"
#include "ipm_road_mapper/core/mapper/lane_topology.h"

namespace ipm_road_mapper {
namespace {

// A lane with control points every 3 m along p(s) over [s0, s1], phantoms included.
template <typename Curve>
MapLane MakeLane(std::uint64_t id, Curve p, double s0, double s1) {
  MapLane lane;
  lane.id = id;
  for (double s = s0 - 3.0; s <= s1 + 3.0 + 1e-9; s += 3.0) lane.control_points_map.push_back(p(s));
  return lane;
}

Eigen::Vector3d OnLine(double s, double y) { return {s, y, 0.0}; }

TEST(LaneTopology, ALineGoingOnInAnotherClassIsLinkedEndToStart) {
  std::vector<MapLane> lanes = {MakeLane(
                                    1, [](double s) { return OnLine(s, 0.0); }, 0, 30),
                                MakeLane(
                                    2, [](double s) { return OnLine(s, 0.0); }, 30, 60)};
  LinkLaneTopology(&lanes);
  EXPECT_EQ(lanes[0].successors, std::vector<std::uint64_t>{2});
  EXPECT_TRUE(lanes[0].predecessors.empty());
  EXPECT_EQ(lanes[1].predecessors, std::vector<std::uint64_t>{1});
  EXPECT_TRUE(lanes[1].successors.empty());
}

TEST(LaneTopology, AForkBranchStartsOnTheLineThatGoesOn) {
  const double a = 15.0 * M_PI / 180.0;
  std::vector<MapLane> lanes = {
      MakeLane(
          1, [](double s) { return OnLine(s, 0.0); }, 0, 90),
      MakeLane(
          2, [a](double s) { return Eigen::Vector3d(30 + s * std::cos(a), s * std::sin(a), 0); }, 0,
          40)};
  LinkLaneTopology(&lanes);
  EXPECT_EQ(lanes[1].predecessors, std::vector<std::uint64_t>{1});
  EXPECT_EQ(lanes[0].successors, std::vector<std::uint64_t>{2});
}

TEST(LaneTopology, DoubleLineHalvesAndDistantLanesAreNotLinked) {
  std::vector<MapLane> lanes = {MakeLane(
                                    1, [](double s) { return OnLine(s, 0.0); }, 0, 60),
                                MakeLane(
                                    2, [](double s) { return OnLine(s, 0.3); }, 10, 50),
                                MakeLane(
                                    3, [](double s) { return OnLine(s, 3.5); }, 60, 90)};
  LinkLaneTopology(&lanes);
  for (const MapLane& lane : lanes) {
    EXPECT_TRUE(lane.predecessors.empty()) << lane.id;
    EXPECT_TRUE(lane.successors.empty()) << lane.id;
  }
}

TEST(LaneTopology, RoundTripsThroughTheMapFile) {
  VectorMap map;
  map.lanes = {MakeLane(
                   1, [](double s) { return OnLine(s, 0.0); }, 0, 30),
               MakeLane(
                   2, [](double s) { return OnLine(s, 0.0); }, 30, 60)};
  LinkLaneTopology(&map.lanes);
  const VectorMap back = VectorMapFromJson(VectorMapToJson(map));
  ASSERT_EQ(back.lanes.size(), 2u);
  EXPECT_EQ(back.lanes[0].successors, std::vector<std::uint64_t>{2});
  EXPECT_EQ(back.lanes[1].predecessors, std::vector<std::uint64_t>{1});
  // A file without the keys (older writers) reads as no topology...
  nlohmann::json j = VectorMapToJson(map);
  j["lanes"][0].erase("successors");
  EXPECT_TRUE(VectorMapFromJson(j).lanes[0].successors.empty());
  // ... one naming a lane outside it (a part of a cut map) keeps the link, and one naming
  // the lane itself is refused.
  j["lanes"][0]["successors"] = nlohmann::json::array({7u});
  EXPECT_EQ(VectorMapFromJson(j).lanes[0].successors, std::vector<std::uint64_t>{7});
  j["lanes"][0]["successors"] = nlohmann::json::array({1u});
  EXPECT_THROW(VectorMapFromJson(j), MapFormatError);
}

}  // namespace
}  // namespace ipm_road_mapper
