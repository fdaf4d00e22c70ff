// Which part of a lane changed: the ChangeLog keeps, per lane, the least control point each
// change since a revision may have moved (0, the whole lane, when a writer reports none), and
// Mapper::ExportChanges carries that index and, when asked, only the lane's tail from a few
// points before it; the points before it are exactly those of the export at that revision.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>

#include "common/road_scene.h"
#include "ipm_road_mapper/core/mapper/mapper.h"

namespace ipm_road_mapper {
namespace {

using namespace test;  // NOLINT: the scene's helpers

TEST(LaneChangeRanges, TheLeastPointNotedSinceARevision) {
  ChangeLog log;
  const std::uint64_t r1 = log.Next(), r2 = log.Next(), r3 = log.Next();
  log.NoteLane(r1, 7, 10);
  log.NoteLane(r2, 7, 30);
  log.NoteLane(r3, 7, 20);
  EXPECT_EQ(log.LaneChangedFrom(7, 0), 10u);
  EXPECT_EQ(log.LaneChangedFrom(7, r1), 20u);  // 30 then 20: the least
  EXPECT_EQ(log.LaneChangedFrom(7, r2), 20u);
  EXPECT_EQ(log.LaneChangedFrom(8, 0), 0u);  // nothing noted: the whole lane
  log.NoteLane(log.Next(), 7, 0);            // a re-fit
  EXPECT_EQ(log.LaneChangedFrom(7, r3), 0u);
  log.NoteRemoved(ElementKind::kLane, 7);  // gone: forgotten
  log.NoteLane(log.Next(), 9, 5);
  log.Clear();
  EXPECT_EQ(log.LaneChangedFrom(9, 0), 0u);
}

TEST(LaneChangeRanges, FirstChangedControlPoint) {
  const std::vector<Eigen::Vector3d> a = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0),
                                          Eigen::Vector3d(2, 0, 0)};
  std::vector<Eigen::Vector3d> b = a;
  EXPECT_EQ(FirstChangedControlPoint(a, b), 3u);
  b.push_back(Eigen::Vector3d(3, 0, 0));
  EXPECT_EQ(FirstChangedControlPoint(a, b), 3u);  // appended
  EXPECT_EQ(FirstChangedControlPoint(b, a), 3u);  // cut
  b[1].y() = 0.01;
  EXPECT_EQ(FirstChangedControlPoint(a, b), 1u);
  b.insert(b.begin(), Eigen::Vector3d(-1, 0, 0));
  EXPECT_EQ(FirstChangedControlPoint(a, b), 0u);  // prepended
}

TEST(LaneChangeRanges, AWriterThatReportsNoRangeChangesTheWholeLane) {
  MapStore store(4.0);
  LaneElement lane;
  lane.id = store.NewId();
  lane.control_points_map.assign(400, Eigen::Vector3d::Zero());
  store.lanes().push_back(lane);
  LaneElement& stored = store.lanes().back();
  store.Touch(&stored, 390);
  const std::uint64_t since = store.changes().revision();
  store.Touch(&stored, 395);
  EXPECT_EQ(store.changes().LaneChangedFrom(stored.id, since), 395u);
  store.Touch(&stored);  // no range
  EXPECT_EQ(store.changes().LaneChangedFrom(stored.id, since), 0u);
  EXPECT_EQ(store.changes().LaneChangedFrom(stored.id, 0), 0u);
}

// Frame k of a 400 m drive at 2 m a frame along a dashed lane at y = 1.8 m (3 m dashes, 6 m
// period, seen from 4 to 35 m ahead).
FrameInput LongLaneFrame(int k) {
  const double x_vehicle = 2.0 * k;
  FrameInput in;
  in.stamp = 100.0 + 0.1 * k;
  in.camera = TestCamera();
  in.T_map_base_odom = PoseAt(x_vehicle);
  in.mask = cv::Mat::zeros(720, 1280, CV_16UC1);
  for (double x = 0.0; x < 440.0; x += 6.0) {
    if (x < x_vehicle + 4.0 || x > x_vehicle + 35.0) continue;
    FillGround(Rect(x, x + 3.0, 1.725, 1.875), in.T_map_base_odom, 2001, &in.mask);
  }
  return in;
}

// That drive with the back end solving windows (results applied to the lanes' slices) and
// the final solve: at every step, each changed lane's points before its first changed one
// are those of the previous export, its tail is the whole lane's from the offset on, and
// once the lane is long its changes start well inside it.
TEST(LaneChangeRanges, ExportedPointsBeforeTheFirstChangedOneAreAsExportedBefore) {
  MapperOptions options;
  options.backend.synchronous = true;
  Mapper mapper(options, TestClasses(), TestExtrinsic());
  ChangesOptions tails;
  tails.lane_context_points = 5;
  std::map<std::uint64_t, std::vector<Eigen::Vector3d>> exported;  // the client's lanes
  std::uint64_t revision = 0;
  std::size_t latest_first_changed = 0, ranged = 0, longest_tail = 0;
  auto step = [&](int k) {
    SCOPED_TRACE("frame " + std::to_string(k));
    const MapChanges whole = mapper.ExportChanges(revision);
    const MapChanges tail = mapper.ExportChanges(revision, tails);
    revision = whole.revision;
    ASSERT_EQ(whole.map.lanes.size(), whole.lane_first_changed.size());
    ASSERT_EQ(tail.map.lanes.size(), whole.map.lanes.size());
    ASSERT_EQ(tail.lane_first_changed, whole.lane_first_changed);
    for (std::uint64_t id : whole.removed_lane_ids) exported.erase(id);
    for (std::size_t i = 0; i < whole.map.lanes.size(); ++i) {
      const MapLane& lane = whole.map.lanes[i];
      const std::size_t first = whole.lane_first_changed[i];
      EXPECT_EQ(whole.lane_offsets[i], 0u);
      const auto before = exported.find(lane.id);
      if (first > 0) {
        ASSERT_NE(before, exported.end()) << "a lane new to the client must come whole";
        ASSERT_LE(first, before->second.size());
        ASSERT_LE(first, lane.control_points_map.size());
        for (std::size_t j = 0; j < first; ++j) {
          EXPECT_EQ(before->second[j], lane.control_points_map[j]) << "point " << j;
        }
        ++ranged;
        latest_first_changed = first;
      }
      const std::size_t offset = tail.lane_offsets[i];
      EXPECT_EQ(offset, first > 5 ? first - 5 : 0);
      const std::vector<Eigen::Vector3d> suffix(lane.control_points_map.begin() + offset,
                                                lane.control_points_map.end());
      EXPECT_EQ(tail.map.lanes[i].control_points_map, suffix);
      // Past the windows' reach (a window and its context, 160 m here), the changed part
      // no longer grows with the lane.
      if (k >= 100) longest_tail = std::max(longest_tail, suffix.size());
      exported[lane.id] = lane.control_points_map;
    }
  };
  for (int k = 0; k < 200; ++k) {
    mapper.ProcessFrame(LongLaneFrame(k));
    step(k);
  }
  EXPECT_GT(ranged, 100u);
  EXPECT_GT(latest_first_changed, 80u);  // of about 140 points
  EXPECT_LE(longest_tail, 75u);          // from about 70 points at frame 100 to 140
  mapper.Finish();
  step(-1);
}

}  // namespace
}  // namespace ipm_road_mapper
