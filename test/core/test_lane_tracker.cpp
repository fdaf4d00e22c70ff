// The lane tracker alone, on observations extracted from rendered masks: one dashed line is
// one spline that grows as the vehicle drives, a short unmatched piece starts nothing, two
// lanes along one line are merged, a gap beyond join_max_gap_m is bridged only where no frame
// saw it, and the export re-fit follows a changed extrinsic.
#include <gtest/gtest.h>

#include "common/lane_fragments.h"
#include "common/road_scene.h"
#include "ipm_road_mapper/core/frontend/instance_extraction.h"
#include "ipm_road_mapper/core/mapper/lane_tracker.h"

namespace ipm_road_mapper {
namespace {

using namespace test;  // NOLINT: the scene's helpers

struct Rig : RoomRig {
  explicit Rig(MapperOptions o = MapperOptions()) : RoomRig(std::move(o)) {}
  void Step(const FrameInput& in) {
    std::optional<Ipm> ipm;
    const FrameObservations obs = Observe(in, TestExtrinsic(), &ipm);
    const FrameRecord& frame = store.AddFrame(in.stamp, in.T_map_base_odom);
    tracker.Update(obs.lanes, frame);
    tracker.DropSpurious(frame.index);
  }
  LaneTracker tracker{options, &store, &counters};
};

// Adds a lane to the store as its writers do: pushed and touched (indexed by place).
void AddLane(RoomRig* rig, LaneElement lane) {
  rig->store.lanes().push_back(std::move(lane));
  rig->store.Touch(&rig->store.lanes().back());
}

double MaxX(const std::vector<Eigen::Vector3d>& cps) {
  double x = -1e9;
  for (std::size_t i = 1; i + 1 < cps.size(); ++i) x = std::max(x, cps[i].x());
  return x;
}

TEST(LaneTracker, OneDashedLineIsOneGrowingSpline) {
  Rig rig;
  rig.Step(RoadFrame(100.0, 0.0, false));
  ASSERT_EQ(rig.store.lanes().size(), 1u);
  const double reach_first = MaxX(rig.store.lanes()[0].control_points_map);
  for (int k = 1; k < 30; ++k) rig.Step(RoadFrame(100.0 + 0.05 * k, 1.0 * k, false));
  ASSERT_EQ(rig.store.lanes().size(), 1u);
  const LaneElement& lane = rig.store.lanes()[0];
  EXPECT_EQ(lane.history.size(), 30u);
  EXPECT_GT(MaxX(lane.control_points_map), reach_first + 20.0);
  for (std::size_t i = 1; i + 1 < lane.control_points_map.size(); ++i) {
    EXPECT_NEAR(lane.control_points_map[i].y(), 1.8, 0.1);
  }
  EXPECT_EQ(rig.counters.lanes_created, 1u);
}

TEST(LaneTracker, OffsetAcrossIsTheFramesPoseErrorAsTheLanesSeeItAndChangesNothing) {
  Rig rig;
  for (int k = 0; k < 10; ++k) rig.Step(RoadFrame(100.0 + 0.05 * k, 1.0 * k, false));
  ASSERT_EQ(rig.store.lanes().size(), 1u);
  const std::vector<Eigen::Vector3d> before = rig.store.lanes()[0].control_points_map;
  // The next frame at an odometry pose 0.3 m to the left of the truth: its line lands 0.3 m
  // left of the lane, and 0.3 m to the right puts it back on.
  FrameInput in = RoadFrame(100.5, 10.0, false);
  std::optional<Ipm> ipm;
  const FrameObservations obs = rig.Observe(in, TestExtrinsic(), &ipm);
  in.T_map_base_odom.translation().y() += 0.3;
  const FrameRecord& frame = rig.store.AddFrame(in.stamp, in.T_map_base_odom);
  const std::optional<double> offset =
      rig.tracker.OffsetAcross(rig.tracker.Associate(obs.lanes, frame), frame);
  ASSERT_TRUE(offset.has_value());
  EXPECT_NEAR(*offset, -0.3, 0.05);
  EXPECT_EQ(rig.store.lanes()[0].control_points_map, before);
  EXPECT_EQ(rig.store.lanes()[0].history.size(), 10u);
  // No lane observed: nothing to say.
  EXPECT_FALSE(rig.tracker.OffsetAcross(rig.tracker.Associate({}, frame), frame).has_value());
}

TEST(LaneTracker, TwoLanesAlongOneLineAreMerged) {
  MapperOptions options;
  options.lanes.merge_every_n_frames = 1;
  Rig rig(options);
  rig.Step(RoadFrame(100.0, 0.0, false));
  ASSERT_EQ(rig.store.lanes().size(), 1u);
  // A second lane of the same class along the same line, 30 m further (a line restarted
  // after a gap): merged into the first at the next frame.
  LaneElement second = rig.store.lanes()[0];
  second.id = rig.store.NewId();
  for (Eigen::Vector3d& c : second.control_points_map) c.x() += 9.0;
  AddLane(&rig, second);
  rig.Step(RoadFrame(100.05, 1.0, false));
  EXPECT_EQ(rig.store.lanes().size(), 1u);
  EXPECT_EQ(rig.counters.lanes_merged, 1u);
  EXPECT_EQ(rig.store.lanes()[0].history.size(), 3u);  // both histories and the new frame
}

// Lanes kilometers long (joined lines on a long drive): the merge compares each with the
// part of the other near its points, and still merges only two lanes along one line.
TEST(LaneTracker, LongLanesMergeAlongOneLineOnly) {
  MapperOptions options;
  options.lanes.merge_every_n_frames = 1;
  Rig rig(options);
  auto straight = [&](double y, double x0, double x1) {
    LaneElement lane;
    lane.id = rig.store.NewId();
    lane.class_id = 1;  // not the scene's dashed line
    for (double x = x0 - 3.0; x <= x1 + 3.0 + 1e-9; x += 3.0) {
      lane.control_points_map.emplace_back(x, y, 0.0);
    }
    return lane;
  };
  AddLane(&rig, straight(-30.0, 0.0, 3000.0));
  AddLane(&rig, straight(-29.9, 1500.0, 4500.0));  // the same line, 1.5 km on
  AddLane(&rig, straight(-26.5, 0.0, 3000.0));     // the next line, 3.5 m beside
  rig.Step(RoadFrame(100.0, 1600.0, false));       // where they overlap (merges are local)
  EXPECT_EQ(rig.counters.lanes_merged, 1u);
  std::size_t on_the_line = 0, beside = 0;
  for (const LaneElement& lane : rig.store.lanes()) {
    if (lane.class_id != 1) continue;
    const double y = lane.control_points_map[1].y();
    if (std::abs(y + 30.0) < 0.5) ++on_the_line;
    if (std::abs(y + 26.5) < 0.5) ++beside;
  }
  EXPECT_EQ(on_the_line, 1u);
  EXPECT_EQ(beside, 1u);
}

// Lanes are never retired, so the per-frame work must not visit the drive's lanes: two lanes
// along one line 2 km behind the vehicle are left alone (the tracker looks at the lanes near
// the vehicle, MapStore::LanesNear), and merged once the vehicle is there again.
TEST(LaneTracker, FarLanesAreLeftAloneUntilTheVehicleIsNear) {
  MapperOptions options;
  options.lanes.merge_every_n_frames = 1;
  Rig rig(options);
  auto straight = [&](double x0, double x1) {
    LaneElement lane;
    lane.id = rig.store.NewId();
    lane.class_id = 1;  // not the scene's dashed line
    for (double x = x0 - 3.0; x <= x1 + 3.0 + 1e-9; x += 3.0) {
      lane.control_points_map.emplace_back(x, -30.0, 0.0);
    }
    return lane;
  };
  AddLane(&rig, straight(2000.0, 2100.0));
  AddLane(&rig, straight(2050.0, 2150.0));  // along the first: one line
  for (int k = 0; k < 5; ++k) rig.Step(RoadFrame(100.0 + 0.05 * k, 1.0 * k, false));
  EXPECT_EQ(rig.counters.lanes_merged, 0u);
  EXPECT_EQ(rig.store.lanes().size(), 3u);  // the two and the scene's line
  rig.Step(RoadFrame(200.0, 2060.0, false));
  EXPECT_EQ(rig.counters.lanes_merged, 1u);
}

// Two fragments of one dashed line across a gap: lane 1 seen in frames 0-39, lane 2 from
// frame 60 on.
void AddFragments(Rig* rig) {
  std::mt19937 rng(7);
  const test::Line line = test::Straight(1.75);
  AddLane(rig, test::MakeLane(rig->store.NewId(), 2, line, 0.0, 40.0, 0, 40, &rng));
  AddLane(rig, test::MakeLane(rig->store.NewId(), 2, line, 46.0, 100.0, 60, 120, &rng));
}

// Frames along x until the store holds `frames`.
void AddFrames(Rig* rig, std::size_t frames) {
  while (rig->store.frames().size() < frames) {
    const double x = static_cast<double>(rig->store.frames().size());
    Eigen::Isometry3d T_map_base = Eigen::Isometry3d::Identity();
    T_map_base.translation().x() = x;
    rig->store.AddFrame(0.05 * x, T_map_base);
  }
}

TEST(LaneTracker, AJunctionIsJoinedOnlineOnceItsDataLeftTheWindows) {
  MapperOptions options;  // back end with PPSR, window of 40 frames: lane context 80 frames
  ASSERT_TRUE(options.lanes.join.enabled);
  Rig rig(options);
  AddFragments(&rig);
  AddFrames(&rig, 140);
  // Frame 60 (lane 2's first) is still in the windows' lane context (from frame 60 on).
  EXPECT_EQ(rig.tracker.SettledBefore(), 60u);
  rig.tracker.JoinFragments(rig.tracker.SettledBefore());
  EXPECT_EQ(rig.store.lanes().size(), 2u);
  EXPECT_EQ(rig.counters.lanes_joined, 0u);
  AddFrames(&rig, 141);  // now it has left: joined
  rig.tracker.JoinFragments(rig.tracker.SettledBefore());
  ASSERT_EQ(rig.store.lanes().size(), 1u);
  EXPECT_EQ(rig.counters.lanes_joined, 1u);
  EXPECT_EQ(rig.store.lanes()[0].history.size(), 100u);
}

TEST(LaneTracker, AtTheEndOrWithoutLaneResidualJunctionsJoinAtOnce) {
  Rig at_end;
  AddFragments(&at_end);
  AddFrames(&at_end, 125);
  at_end.tracker.JoinFragments();  // the end of the drive: everything is settled
  EXPECT_EQ(at_end.store.lanes().size(), 1u);
  for (const bool backend_enabled : {false, true}) {
    MapperOptions options;
    options.backend.enabled = backend_enabled;
    options.backend.lane_residual = LaneResidual::kNone;  // no window uses lane data
    Rig rig(options);
    AddFragments(&rig);
    AddFrames(&rig, 125);
    EXPECT_EQ(rig.tracker.SettledBefore(), 125u);
    rig.tracker.JoinFragments(rig.tracker.SettledBefore());
    EXPECT_EQ(rig.store.lanes().size(), 1u) << backend_enabled;
  }
}

// Two fragments of one line 30 m apart (beyond join_max_gap_m, within
// join_max_hidden_gap_m), seen in frames 0-39 and 70-109 of a drive along x, heading `yaw`.
void AddFarFragments(Rig* rig, double yaw) {
  std::mt19937 rng(9);
  const test::Line line = test::Straight(1.75);
  AddLane(rig, test::MakeLane(rig->store.NewId(), 2, line, 0.0, 40.0, 0, 40, &rng));
  AddLane(rig, test::MakeLane(rig->store.NewId(), 2, line, 70.0, 110.0, 70, 110, &rng));
  for (std::size_t i = 0; i < 125; ++i) {
    const Eigen::Isometry3d T_map_base = Eigen::Translation3d(static_cast<double>(i), 0.0, 0.0) *
                                         Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ());
    rig->store.AddFrame(0.05 * static_cast<double>(i), T_map_base);
  }
}

TEST(LaneTracker, ALongGapIsJoinedOnlyWhereNoFrameSawIt) {
  // The camera looks along the road: it saw the gap empty, the line ended there.
  Rig seen;
  AddFarFragments(&seen, 0.0);
  seen.tracker.SetCamera(TestCamera(), TestExtrinsic());
  seen.tracker.JoinFragments();
  EXPECT_EQ(seen.store.lanes().size(), 2u);
  // No camera known: the gap cannot be told hidden.
  Rig unknown;
  AddFarFragments(&unknown, -M_PI / 2);
  unknown.tracker.JoinFragments();
  EXPECT_EQ(unknown.store.lanes().size(), 2u);
  // The camera looked away from the line (to the right of a line on the left) the whole
  // time: the gap was hidden, so the fragments are one line, joined at the end of the drive
  // (online, with every junction settled, they are left apart: no window ties to the bridge).
  MapperOptions settled;
  settled.backend.lane_residual = LaneResidual::kNone;
  Rig hidden(settled);
  AddFarFragments(&hidden, -M_PI / 2);
  hidden.tracker.SetCamera(TestCamera(), TestExtrinsic());
  ASSERT_EQ(hidden.tracker.SettledBefore(), 125u);
  hidden.tracker.JoinFragments(hidden.tracker.SettledBefore());
  EXPECT_EQ(hidden.store.lanes().size(), 2u);
  hidden.tracker.JoinFragments();
  ASSERT_EQ(hidden.store.lanes().size(), 1u);
  EXPECT_EQ(hidden.counters.lanes_joined_hidden_gap, 1u);
  EXPECT_EQ(hidden.store.lanes()[0].history.size(), 80u);
  // Hidden, but longer than join_max_hidden_gap_m: apart.
  MapperOptions short_reach;
  short_reach.lanes.join.max_hidden_gap_m = 25.0;
  Rig too_long(short_reach);
  AddFarFragments(&too_long, -M_PI / 2);
  too_long.tracker.SetCamera(TestCamera(), TestExtrinsic());
  too_long.tracker.JoinFragments();
  EXPECT_EQ(too_long.store.lanes().size(), 2u);
}

TEST(LaneTracker, AClassFlickeringBetweenDashedAndSolidMakesNoDuplicate) {
  // One dashed line whose class reads solid (class 1) in every third frame.
  Rig rig;
  for (int k = 0; k < 30; ++k) {
    const FrameInput in = RoadFrame(100.0 + 0.05 * k, 1.0 * k, false);
    std::optional<Ipm> ipm;
    FrameObservations obs = rig.Observe(in, TestExtrinsic(), &ipm);
    ASSERT_EQ(obs.lanes.size(), 1u);
    if (k % 3 == 1) obs.lanes[0].class_id = 1;
    const FrameRecord& frame = rig.store.AddFrame(in.stamp, in.T_map_base_odom);
    rig.tracker.Update(obs.lanes, frame);
    rig.tracker.DropSpurious(frame.index);
  }
  ASSERT_EQ(rig.store.lanes().size(), 1u);
  EXPECT_EQ(rig.store.lanes()[0].class_id, 2);
  EXPECT_GE(rig.counters.lane_observations_other_class, 9u);
  // A line that goes on in another class past the lane's end still starts a lane.
  const FrameInput ahead = RoadFrame(102.0, 80.0, false);
  std::optional<Ipm> ipm;
  FrameObservations obs = rig.Observe(ahead, TestExtrinsic(), &ipm);
  ASSERT_EQ(obs.lanes.size(), 1u);
  obs.lanes[0].class_id = 1;
  rig.tracker.Update(obs.lanes, rig.store.AddFrame(ahead.stamp, ahead.T_map_base_odom));
  EXPECT_EQ(rig.store.lanes().size(), 2u);
}

TEST(LaneTracker, ShortUnmatchedPieceStartsNoLane) {
  Rig rig;
  FrameInput in = RoadFrame(100.0, 0.0, false);
  in.mask.setTo(0);
  FillGround(Rect(8.0, 9.0, 1.725, 1.875), in.T_map_base_odom, 2001, &in.mask);  // 1 m dash
  rig.Step(in);
  EXPECT_TRUE(rig.store.lanes().empty());
  EXPECT_EQ(rig.counters.lane_observations_unused, 1u);
}

TEST(LaneTracker, RefitFollowsTheExtrinsic) {
  Rig rig;
  for (int k = 0; k < 5; ++k) rig.Step(RoadFrame(100.0 + 0.05 * k, 1.0 * k, false));
  const LaneElement& lane = rig.store.lanes()[0];
  const auto same = rig.tracker.RefitControlPoints(lane, TestCamera(), TestExtrinsic());
  Eigen::Isometry3d lifted = TestExtrinsic();
  lifted.translation().z() += 0.3;  // a higher camera puts ground points farther out
  const auto wider = rig.tracker.RefitControlPoints(lane, TestCamera(), lifted);
  ASSERT_GE(same.size(), 4u);
  ASSERT_GE(wider.size(), 4u);
  EXPECT_NEAR(same[1].y(), 1.8, 0.1);
  EXPECT_GT(wider[1].y(), same[1].y() + 0.1);
}

}  // namespace
}  // namespace ipm_road_mapper
