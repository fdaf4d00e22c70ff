// Change tracking and the incremental export: MapStore::Touch gives every change a newer
// revision, a retired marking costs an export nothing until it changes, elements that leave
// the map are reported removed, and Mapper::ExportChanges applied step by step to a copy of
// the map gives what ExportMap gives (nothing missed) on a drive with the back end solving
// windows, retiring markings and the final solve moving them.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>

#include "common/road_scene.h"
#include "ipm_road_mapper/core/mapper/mapper.h"
#include "ipm_road_mapper/core/mapper/marking_tracker.h"

namespace ipm_road_mapper {
namespace {

using namespace test;  // NOLINT: the scene's helpers

MarkingElement Marking(MapStore* store, double x) {
  MarkingElement m;
  m.id = store->NewId();
  for (int i = 0; i < 4; ++i) m.corners_map[i] = Eigen::Vector3d(x + (i % 2), i / 2, 0.0);
  return m;
}

bool Contains(const std::vector<std::uint64_t>& ids, std::uint64_t id) {
  return std::find(ids.begin(), ids.end(), id) != ids.end();
}

std::vector<std::uint64_t> RetiredIdsSince(const MapStore& store, std::uint64_t since) {
  std::vector<std::uint64_t> ids;
  for (const auto& [revision, id] : store.changes().RetiredSince(since)) {
    const std::int64_t index = store.RetiredIndexOf(id);
    if (index >= 0 && store.retired_markings()[index].revision == revision) ids.push_back(id);
  }
  return ids;
}

TEST(ChangeTracking, EveryTouchIsANewerRevision) {
  MapStore store(4.0);
  store.markings().push_back(Marking(&store, 0.0));
  LaneElement lane;
  lane.id = store.NewId();
  store.lanes().push_back(lane);
  EXPECT_EQ(store.changes().revision(), 0u);
  store.Touch(&store.markings()[0]);
  store.Touch(&store.lanes()[0]);
  EXPECT_EQ(store.markings()[0].revision, 1u);
  EXPECT_EQ(store.lanes()[0].revision, 2u);
  store.Touch(&store.markings()[0]);
  EXPECT_EQ(store.markings()[0].revision, 3u);
  EXPECT_EQ(store.changes().revision(), 3u);
}

TEST(ChangeTracking, RetiredMarkingIsLoggedWhenRetiredAndWhenChangedOnly) {
  MapStore store(4.0);
  for (double x : {0.0, 20.0}) store.markings().push_back(Marking(&store, x));
  for (MarkingElement& m : store.markings()) m.retired = true;
  store.RetireMarkings(1);
  ASSERT_EQ(store.retired_markings().size(), 2u);
  const std::uint64_t a = store.retired_markings()[0].id, b = store.retired_markings()[1].id;
  EXPECT_EQ(RetiredIdsSince(store, 0), (std::vector<std::uint64_t>{a, b}));
  const std::uint64_t r = store.changes().revision();
  EXPECT_TRUE(RetiredIdsSince(store, r).empty());  // untouched since: nothing to export
  store.Touch(&store.retired_markings()[1]);       // e.g. the final solve moved it
  EXPECT_EQ(RetiredIdsSince(store, r), (std::vector<std::uint64_t>{b}));
  // Touched twice: listed once (the older entry is stale).
  store.Touch(&store.retired_markings()[1]);
  EXPECT_EQ(RetiredIdsSince(store, r), (std::vector<std::uint64_t>{b}));
}

TEST(ChangeTracking, ElementsThatLeaveTheMapAreReportedRemoved) {
  MapStore store(4.0);
  for (double x : {0.0, 20.0, 40.0}) store.markings().push_back(Marking(&store, x));
  LaneElement lane;
  lane.id = store.NewId();
  store.lanes().push_back(lane);
  store.NoteRemovals();
  const std::uint64_t r = store.changes().revision();
  const std::uint64_t kept = store.markings()[0].id, retired = store.markings()[1].id;
  const std::uint64_t dropped = store.markings()[2].id;
  store.markings()[1].retired = true;
  store.RetireMarkings(1);  // leaves the live set, stays in the map
  store.markings().pop_back();
  store.lanes().clear();
  store.NoteRemovals();
  const std::vector<std::uint64_t> removed = store.changes().RemovedSince(ElementKind::kMarking, r);
  EXPECT_EQ(removed, (std::vector<std::uint64_t>{dropped}));
  EXPECT_FALSE(Contains(removed, kept));
  EXPECT_FALSE(Contains(removed, retired));
  EXPECT_EQ(store.changes().RemovedSince(ElementKind::kLane, r),
            (std::vector<std::uint64_t>{lane.id}));
  // Revived, then gone before the next NoteRemovals: still reported.
  const std::uint64_t r2 = store.changes().revision();
  store.ReviveMarking(0);
  store.markings().pop_back();
  store.NoteRemovals();
  EXPECT_EQ(store.changes().RemovedSince(ElementKind::kMarking, r2),
            (std::vector<std::uint64_t>{retired}));
}

TEST(ChangeTracking, MergedAwayMarkingIsReportedRemovedAndTheSurvivorChanged) {
  RoomRig rig{MapperOptions()};
  MarkingTracker tracker(rig.options, &rig.store, &rig.counters);
  auto step = [&](const FrameInput& in) {
    std::optional<Ipm> ipm;
    FrameObservations obs = rig.Observe(in, TestExtrinsic(), &ipm);
    const FrameRecord& frame = rig.store.AddFrame(in.stamp, in.T_map_base_odom);
    tracker.Update(*ipm, frame, &obs.markings);
    rig.store.NoteRemovals();
  };
  step(RoadFrame(100.0, 0.0));
  ASSERT_EQ(rig.store.markings().size(), 1u);
  MarkingElement copy = rig.store.markings()[0];  // a duplicate 0.3 m beside it
  copy.id = rig.store.NewId();
  for (Eigen::Vector3d& c : copy.corners_map) c.y() += 0.3;
  rig.store.markings().push_back(copy);
  rig.store.NoteRemovals();
  const std::uint64_t r = rig.store.changes().revision();
  const std::uint64_t first = rig.store.markings()[0].id;
  step(RoadFrame(100.05, 0.5));
  ASSERT_EQ(rig.store.markings().size(), 1u);
  const std::vector<std::uint64_t> removed =
      rig.store.changes().RemovedSince(ElementKind::kMarking, r);
  ASSERT_EQ(removed.size(), 1u);
  EXPECT_TRUE(removed[0] == first || removed[0] == copy.id);
  EXPECT_NE(rig.store.markings()[0].id, removed[0]);
  EXPECT_GT(rig.store.markings()[0].revision, r);
}

TEST(ChangeTracking, UpdatedMarkingAppearsUntouchedOneDoesNot) {
  MapperOptions options;
  options.backend.enabled = false;
  Mapper mapper(options, TestClasses(), TestExtrinsic());
  for (int k = 0; k < 6; ++k) mapper.ProcessFrame(RoadFrame(100.0 + 0.05 * k, 0.5 * k));
  const MapChanges all = mapper.ExportChanges(0);
  EXPECT_TRUE(all.complete);
  const VectorMap full = mapper.ExportMap();
  ASSERT_EQ(all.map.markings.size(), full.markings.size());
  ASSERT_EQ(full.markings.size(), 1u);
  ASSERT_EQ(all.map.lanes.size(), full.lanes.size());
  ASSERT_FALSE(full.lanes.empty());
  const std::uint64_t r = all.revision;
  EXPECT_TRUE(mapper.ExportChanges(r).map.markings.empty());  // nothing since
  // Without a lane residual lanes are re-fit at export to the current extrinsic and poses:
  // every lane is listed.
  EXPECT_EQ(mapper.ExportChanges(r).map.lanes.size(), full.lanes.size());
  // The lane is seen again, the arrow is not: the arrow does not come out.
  mapper.ProcessFrame(RoadFrame(100.3, 3.0, /*with_arrow=*/false));
  const MapChanges next = mapper.ExportChanges(r);
  EXPECT_FALSE(next.complete);
  EXPECT_TRUE(next.map.markings.empty());
  EXPECT_GT(next.revision, r);
  // The arrow again: it changes (one more observation).
  mapper.ProcessFrame(RoadFrame(100.35, 3.5));
  const MapChanges arrow = mapper.ExportChanges(next.revision);
  ASSERT_EQ(arrow.map.markings.size(), 1u);
  EXPECT_EQ(arrow.map.markings[0].observations, full.markings[0].observations + 1);
}

TEST(ChangeTracking, ResetMakesTheNextChangesComplete) {
  MapperOptions options;
  options.backend.enabled = false;
  Mapper mapper(options, TestClasses(), TestExtrinsic());
  for (int k = 0; k < 4; ++k) mapper.ProcessFrame(RoadFrame(100.0 + 0.05 * k, 0.5 * k));
  const std::uint64_t r = mapper.revision();
  mapper.Reset();
  EXPECT_TRUE(mapper.ExportChanges(r).complete);
  EXPECT_TRUE(mapper.ExportChanges(r).map.markings.empty());
}

// A client's copy kept by applying changes.
struct Mirror {
  std::map<std::uint64_t, MapMarking> markings;
  std::map<std::uint64_t, MapLane> lanes;
  void Apply(const MapChanges& c) {
    if (c.complete) {
      markings.clear();
      lanes.clear();
    }
    for (std::uint64_t id : c.removed_marking_ids) markings.erase(id);
    for (std::uint64_t id : c.removed_lane_ids) lanes.erase(id);
    for (const MapMarking& m : c.map.markings) markings[m.id] = m;
    for (const MapLane& l : c.map.lanes) lanes[l.id] = l;
  }
};

void ExpectMirrors(const Mirror& mirror, const VectorMap& full, int frame) {
  SCOPED_TRACE("frame " + std::to_string(frame));
  ASSERT_EQ(mirror.markings.size(), full.markings.size());
  ASSERT_EQ(mirror.lanes.size(), full.lanes.size());
  for (const MapMarking& m : full.markings) {
    const auto it = mirror.markings.find(m.id);
    ASSERT_NE(it, mirror.markings.end());
    EXPECT_EQ(it->second.observations, m.observations);
    EXPECT_EQ(it->second.last_seen, m.last_seen);
    EXPECT_EQ(it->second.sides_measured, m.sides_measured);
    for (int i = 0; i < 4; ++i) EXPECT_EQ(it->second.corners_map[i], m.corners_map[i]);
  }
  for (const MapLane& l : full.lanes) {
    const auto it = mirror.lanes.find(l.id);
    ASSERT_NE(it, mirror.lanes.end());
    EXPECT_EQ(it->second.observations, l.observations);
    EXPECT_EQ(it->second.control_points_map, l.control_points_map);
  }
}

TEST(ChangeTracking, ChangesAppliedStepByStepGiveTheFullExport) {
  MapperOptions options;
  options.backend.synchronous = true;  // windows solved, results applied, markings retired
  Mapper mapper(options, TestClasses(), TestExtrinsic());
  Mirror mirror;
  std::uint64_t revision = 0;
  std::size_t retired_seen = 0;
  for (int k = 0; k < 110; ++k) {
    // The arrow seen from x = 0 on (missed now and then), then behind: it retires.
    mapper.ProcessFrame(RoadFrame(100.0 + 0.05 * k, 1.0 * k, k % 7 != 3));
    const MapChanges changes = mapper.ExportChanges(revision);
    mirror.Apply(changes);
    revision = changes.revision;
    ExpectMirrors(mirror, mapper.ExportMap(), k);
    retired_seen = std::max(retired_seen, mapper.map().retired_markings.size());
  }
  mapper.Finish();
  mirror.Apply(mapper.ExportChanges(revision));
  ExpectMirrors(mirror, mapper.ExportMap(), -1);
  EXPECT_GT(mapper.counters().results_applied, 0u);
  EXPECT_GT(retired_seen, 0u);
}

}  // namespace
}  // namespace ipm_road_mapper
