// The control points no pixel measured (lane_unmeasured.h): a join across a gap no frame saw
// flags exactly the bridge's points, the flags follow the points through a later join and
// the lane's growth at its start, and the export gives them as ranges of the exported points.
#include <gtest/gtest.h>

#include <random>

#include "common/lane_fragments.h"
#include "ipm_road_mapper/core/map/index_ranges.h"
#include "ipm_road_mapper/core/mapper/lane_join.h"
#include "ipm_road_mapper/core/mapper/lane_unmeasured.h"

namespace ipm_road_mapper {
namespace {

using Ranges = std::vector<IndexRange>;
using ExportRanges = std::vector<std::pair<std::size_t, std::size_t>>;

test::Line Straight() {
  return [](double s) { return Eigen::Vector3d(s, 1.75, 0.0); };
}

TEST(LaneUnmeasured, RangesOfFlagsAreMaximalRuns) {
  EXPECT_TRUE(RangesOfFlags<std::int64_t>({}, 0).empty());
  EXPECT_TRUE(RangesOfFlags<std::int64_t>({false, false}, 3).empty());
  EXPECT_EQ(RangesOfFlags<std::int64_t>({true, true, false, true, false, true, true, true}, -2),
            (Ranges{{-2, -1}, {1, 1}, {3, 5}}));
}

TEST(LaneUnmeasured, AJoinThroughAHiddenGapFlagsTheBridgeOnly) {
  std::mt19937 rng(1);
  const LaneElement a = test::MakeLane(1, 1, Straight(), 0.0, 30.0, 0, 30, &rng);
  const LaneElement b = test::MakeLane(2, 1, Straight(), 50.0, 80.0, 50, 80, &rng);
  const std::vector<Eigen::Vector3d> bridge = {
      {35.0, 1.75, 0.0}, {40.0, 1.75, 0.0}, {45.0, 1.75, 0.0}};
  const auto joined = JoinLanesThrough(a, b, bridge);
  ASSERT_TRUE(joined.has_value());
  // a's points but its end phantom, then the bridge.
  const std::int64_t first =
      joined->first_cp_index + static_cast<std::int64_t>(a.control_points_map.size()) - 1;
  EXPECT_EQ(joined->unmeasured_cps, (Ranges{{first, first + 2}}));
  for (std::size_t i = 0; i < joined->control_points_map.size(); ++i) {
    const bool on_bridge =
        joined->control_points_map[i].x() > 31.0 && joined->control_points_map[i].x() < 49.0;
    EXPECT_EQ(ControlPointUnmeasured(*joined, i), on_bridge) << i;
  }
}

TEST(LaneUnmeasured, FlagsFollowTheirPointsThroughALaterJoinAndGrowth) {
  std::mt19937 rng(2);
  const LaneElement a = test::MakeLane(1, 1, Straight(), 0.0, 30.0, 0, 30, &rng);
  const LaneElement b = test::MakeLane(2, 1, Straight(), 50.0, 80.0, 50, 80, &rng);
  const LaneElement c = test::MakeLane(3, 1, Straight(), 92.0, 120.0, 92, 120, &rng);
  const std::vector<Eigen::Vector3d> bridge = {{40.0, 1.75, 0.0}};
  auto ab = JoinLanesThrough(a, b, bridge);
  ASSERT_TRUE(ab.has_value());
  ab->last_frame = 80;
  // The lane grew at its start by two points: the global indices of its points stay.
  ab->first_cp_index -= 2;
  ab->control_points_map.insert(ab->control_points_map.begin(), {Eigen::Vector3d(-9.0, 1.75, 0.0),
                                                                 Eigen::Vector3d(-6.0, 1.75, 0.0)});
  ASSERT_TRUE(LaneContinues(*ab, c, LaneJoinOptions(), AssociationOptions()));
  const auto abc = JoinLanes(*ab, c, LaneJoinOptions(), AssociationOptions(), 3.0);
  ASSERT_TRUE(abc.has_value());
  // The bridge at x 40 is still the one point flagged from ab, and JoinLanes' own bridge
  // towards c's start at 92 m (interpolated from ab's last point within its data, whose end
  // model ends before its last control point at 80 m) is flagged too.
  std::vector<double> flagged_x;
  for (std::size_t i = 0; i < abc->control_points_map.size(); ++i) {
    if (ControlPointUnmeasured(*abc, i)) flagged_x.push_back(abc->control_points_map[i].x());
  }
  ASSERT_GE(flagged_x.size(), 3u);
  EXPECT_NEAR(flagged_x.front(), 40.0, 1e-9);
  for (std::size_t k = 1; k < flagged_x.size(); ++k) {
    EXPECT_GT(flagged_x[k], 75.0) << k;
    EXPECT_LT(flagged_x[k], 92.0) << k;
  }
}

TEST(LaneUnmeasured, TheExportGivesRangesOfTheExportedPoints) {
  LaneElement lane;
  lane.first_cp_index = -4;
  lane.control_points_map.resize(20);
  lane.unmeasured_cps = {{-2, 0}, {5, 7}};  // local 2-4 and 9-11
  EXPECT_EQ(ExportedUnmeasured(lane, 0, 20), (ExportRanges{{2, 4}, {9, 11}}));
  // A tail from local 3: local 3-4 and 9-11 are its 0-1 and 6-8.
  EXPECT_EQ(ExportedUnmeasured(lane, 3, 17), (ExportRanges{{0, 1}, {6, 8}}));
  // A tail past both, and none.
  EXPECT_TRUE(ExportedUnmeasured(lane, 12, 8).empty());
  EXPECT_TRUE(ExportedUnmeasured(lane, 0, 0).empty());
  // Clipped to the exported count.
  EXPECT_EQ(ExportedUnmeasured(lane, 0, 10), (ExportRanges{{2, 4}, {9, 9}}));
}

}  // namespace
}  // namespace ipm_road_mapper
