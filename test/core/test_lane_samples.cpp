// A map lane's samples and its unmeasured ranges (lane_samples.h): a laid stretch runs from
// the last measured control point before it to the next; a tail's flags replace the lane's
// ranges from its first point on and keep those before.
#include <gtest/gtest.h>

#include "ipm_road_mapper/core/map/lane_samples.h"

namespace ipm_road_mapper {
namespace {

using Ranges = std::vector<std::pair<std::size_t, std::size_t>>;

MapLane Straight(int points) {
  MapLane lane;
  for (int i = 0; i < points; ++i) lane.control_points_map.emplace_back(2.0 * i - 2.0, 0.0, 0.0);
  return lane;
}

TEST(LaneSamples, ALaidStretchRunsFromTheLastMeasuredPointToTheNext) {
  MapLane lane = Straight(12);  // curve x 0 .. 18 m
  lane.unmeasured = {{4, 5}};   // x 6 and 8 m
  const std::vector<bool> flags = UnmeasuredPointFlags(lane);
  ASSERT_EQ(flags.size(), 12u);
  EXPECT_TRUE(flags[4] && flags[5]);
  EXPECT_FALSE(flags[3] || flags[6]);
  const LaneSamples samples = SampleLane(lane.control_points_map, flags, 0.5);
  ASSERT_EQ(samples.points.size(), samples.unmeasured.size());
  int laid = 0;
  for (std::size_t k = 0; k < samples.points.size(); ++k) {
    const double x = samples.points[k].x();
    if (x > 4.1 && x < 9.9) {
      EXPECT_TRUE(samples.unmeasured[k]) << x;
    }
    if (x < 3.9 || x > 10.1) {
      EXPECT_FALSE(samples.unmeasured[k]) << x;
    }
    laid += samples.unmeasured[k] ? 1 : 0;
  }
  EXPECT_NEAR(laid * 0.5, 6.0, 0.6);  // x 4 .. 10 m
  EXPECT_THROW(SampleLane(lane.control_points_map, {true}, 0.5), std::invalid_argument);
}

TEST(LaneSamples, ATailsFlagsReplaceTheRangesFromItsFirstPoint) {
  MapLane lane = Straight(20);
  lane.unmeasured = {{2, 3}, {8, 12}, {15, 16}};
  // A tail from point 10: the range through it is cut at 9, the later one replaced.
  SetUnmeasuredFrom(10, {false, true, true, false, false, false, false, false, false, false},
                    &lane);
  EXPECT_EQ(lane.unmeasured, (Ranges{{2, 3}, {8, 9}, {11, 12}}));
  // A tail whose first point continues the range before it merges with it.
  SetUnmeasuredFrom(10, {true, false}, &lane);
  EXPECT_EQ(lane.unmeasured, (Ranges{{2, 3}, {8, 10}}));
  // No flags: every range from the first point on goes.
  SetUnmeasuredFrom(3, {}, &lane);
  EXPECT_EQ(lane.unmeasured, (Ranges{{2, 2}}));
  SetUnmeasuredFrom(0, {}, &lane);
  EXPECT_TRUE(lane.unmeasured.empty());
}

}  // namespace
}  // namespace ipm_road_mapper
