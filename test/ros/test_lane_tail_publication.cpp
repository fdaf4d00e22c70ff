// The publication of a long lane from the core's changed-range export: a lane kilometers long
// that changed at its end gives a patch from near its end, and the builders fingerprint,
// convert and draw a bounded number of points whatever the lane's length (counted, not
// timed); a change at its start, a re-fit, or a writer that reported no range publishes the
// whole lane; the messages are those the whole-map way gives; a tail without the context the
// builders need is refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <stdexcept>
#include <vector>

#include "ipm_road_mapper/core/mapper/map_store.h"
#include "ipm_road_mapper/ros/marker_builder.h"
#include "ipm_road_mapper/ros/vector_map_delta_builder.h"
#include "ros/message_bytes.h"

namespace ipm_road_mapper {
namespace {

using test::Bytes;
using test::MarkerSet;

// A straight lane of `points` control points 3 m apart, gently curved in y.
MapLane Lane(std::size_t points) {
  MapLane lane;
  lane.id = 5;
  lane.class_id = 2;
  lane.class_name = "lane_white_dashed";
  lane.style = "dashed";
  lane.observations = 10;
  lane.first_seen = 100.0;
  lane.last_seen = 110.0;
  for (std::size_t i = 0; i < points; ++i) {
    const double x = 3.0 * static_cast<double>(i);
    lane.control_points_map.emplace_back(x, 0.001 * x, 0.0);
  }
  return lane;
}

// The core's changes of `after` since `before` with the first changed point `first_changed`:
// the tail from the builders' context before it (or the whole lane when `tail` is false).
MapChanges Changes(const MapLane& after, std::size_t first_changed, std::size_t context,
                   bool tail = true) {
  MapChanges changes;
  changes.since = 1;
  changes.revision = 2;
  const std::size_t offset = tail && first_changed > context ? first_changed - context : 0;
  MapLane part = after;
  part.control_points_map.assign(after.control_points_map.begin() + offset,
                                 after.control_points_map.end());
  changes.map.lanes.push_back(part);
  changes.lane_first_changed.push_back(first_changed);
  changes.lane_offsets.push_back(offset);
  return changes;
}

MapChanges Complete(const MapLane& lane) {
  MapChanges changes;
  changes.complete = true;
  changes.revision = 1;
  changes.map.lanes.push_back(lane);
  changes.lane_first_changed.push_back(0);
  changes.lane_offsets.push_back(0);
  return changes;
}

VectorMap MapOf(const MapLane& lane) {
  VectorMap map;
  map.lanes.push_back(lane);
  return map;
}

// What publishing `before` then `after` (changed from `first_changed` on) costs and sends,
// checked against the whole-map way.
struct Published {
  ipm_road_mapper::VectorMapDelta delta;
  VectorMapDeltaBuilder::Work delta_work;
  MarkerBuilder::Work marker_work;
};

Published Publish(const MapLane& before, const MapLane& after, std::size_t first_changed,
                  bool tail = true) {
  VectorMapDeltaBuilder deltas, old_deltas;
  MarkerBuilder markers, old_markers;
  const std::size_t context = std::max(deltas.lane_context_points(), markers.lane_context_points());
  const ros::Time stamp(1.0);
  deltas.Build(Complete(before), "map", stamp);
  markers.Build(Complete(before), "map", stamp);
  old_deltas.Build(MapOf(before), "map", stamp);
  old_markers.Build(MapOf(before), "map", stamp, MarkerBuilder::Mode::kChanges);
  const MapChanges changes = Changes(after, first_changed, context, tail);
  Published out;
  out.delta = deltas.Build(changes, "map", stamp);
  const visualization_msgs::MarkerArray array = markers.Build(changes, "map", stamp);
  out.delta_work = deltas.last_work();
  out.marker_work = markers.last_work();
  EXPECT_EQ(Bytes(out.delta), Bytes(old_deltas.Build(MapOf(after), "map", stamp)));
  EXPECT_EQ(MarkerSet(array), MarkerSet(old_markers.Build(MapOf(after), "map", stamp,
                                                          MarkerBuilder::Mode::kChanges)));
  return out;
}

// The lane's last 3 points moved, one appended, and one more observation.
MapLane GrownAtItsEnd(const MapLane& lane) {
  MapLane after = lane;
  std::vector<Eigen::Vector3d>& cps = after.control_points_map;
  for (std::size_t i = cps.size() - 3; i < cps.size(); ++i) cps[i].y() += 0.05;
  cps.push_back(cps.back() + Eigen::Vector3d(3.0, 0.0, 0.0));
  ++after.observations;
  after.last_seen += 0.1;
  return after;
}

TEST(LaneTailPublication, ALongLaneChangedAtItsEndCostsItsEnd) {
  // 1 km and 3 km lanes (multiples of the 16-point chunks: the same chunk alignment).
  const std::size_t km1 = 336, km3 = 1008;
  const Published one = Publish(Lane(km1), GrownAtItsEnd(Lane(km1)), km1 - 3);
  const Published three = Publish(Lane(km3), GrownAtItsEnd(Lane(km3)), km3 - 3);
  ASSERT_EQ(three.delta.lanes.size(), 1u);
  const auto& patch = three.delta.lanes.front();
  EXPECT_GE(patch.first_index, km3 - 3 - 16);  // the changed point's chunk
  EXPECT_LE(patch.first_index, km3 - 3);
  EXPECT_EQ(patch.first_index + patch.control_points.size(), km3 + 1);
  // Bounded, and the same at 1 and 3 km.
  EXPECT_LE(three.delta_work.points_fingerprinted, 32u);
  EXPECT_LE(three.delta_work.points_converted, 20u);
  EXPECT_LE(three.marker_work.points_fingerprinted, 40u);
  EXPECT_LE(three.marker_work.points_drawn, 40u);
  EXPECT_EQ(three.delta_work.points_fingerprinted, one.delta_work.points_fingerprinted);
  EXPECT_EQ(three.delta_work.points_converted, one.delta_work.points_converted);
  EXPECT_EQ(three.marker_work.points_fingerprinted, one.marker_work.points_fingerprinted);
  EXPECT_EQ(three.marker_work.points_drawn, one.marker_work.points_drawn);
  // The same change sent as the whole lane (the default export) publishes the same.
  const Published whole = Publish(Lane(km3), GrownAtItsEnd(Lane(km3)), km3 - 3, false);
  EXPECT_EQ(Bytes(whole.delta), Bytes(three.delta));
  EXPECT_EQ(whole.delta_work.points_fingerprinted, three.delta_work.points_fingerprinted);
}

TEST(LaneTailPublication, AChangeAtTheStartPublishesTheWholeLane) {
  const std::size_t n = 1008;
  MapLane after = Lane(n);
  after.control_points_map.insert(after.control_points_map.begin(), Eigen::Vector3d(-3, 0, 0));
  const Published p = Publish(Lane(n), after, 0);
  ASSERT_EQ(p.delta.lanes.size(), 1u);
  EXPECT_EQ(p.delta.lanes.front().first_index, 0u);
  EXPECT_EQ(p.delta.lanes.front().control_points.size(), n + 1);
  EXPECT_EQ(p.delta_work.points_fingerprinted, n + 1);
}

TEST(LaneTailPublication, AReFitPublishesTheWholeLane) {
  const std::size_t n = 1008;
  MapLane after = Lane(n);
  for (Eigen::Vector3d& p : after.control_points_map) p.y() += 0.01;
  const Published p = Publish(Lane(n), after, 0);
  ASSERT_EQ(p.delta.lanes.size(), 1u);
  EXPECT_EQ(p.delta.lanes.front().first_index, 0u);
  EXPECT_EQ(p.delta.lanes.front().control_points.size(), n);
}

TEST(LaneTailPublication, AWriterThatReportsNoRangePublishesTheWholeLane) {
  const std::size_t n = 1008;
  // The core's log: a ranged change, then one from a writer that reports none.
  MapStore store(4.0);
  LaneElement element;
  element.id = 5;
  element.control_points_map = Lane(n).control_points_map;
  store.lanes().push_back(element);
  store.Touch(&store.lanes().back(), n - 3);
  const std::uint64_t since = store.changes().revision();
  store.Touch(&store.lanes().back());
  const std::size_t first_changed = store.changes().LaneChangedFrom(element.id, since);
  EXPECT_EQ(first_changed, 0u);
  // Every chunk is compared again: the patch is as small as the change, the cost the lane's.
  const Published p = Publish(Lane(n), GrownAtItsEnd(Lane(n)), first_changed);
  ASSERT_EQ(p.delta.lanes.size(), 1u);
  EXPECT_GE(p.delta.lanes.front().first_index, n - 3 - 16);
  EXPECT_EQ(p.delta_work.points_fingerprinted, n + 1);
}

TEST(LaneTailPublication, ATailWithoutItsChunksContextIsRefused) {
  const std::size_t n = 1008;
  VectorMapDeltaBuilder deltas;
  MarkerBuilder markers;
  const ros::Time stamp(1.0);
  deltas.Build(Complete(Lane(n)), "map", stamp);
  markers.Build(Complete(Lane(n)), "map", stamp);
  const MapChanges changes = Changes(GrownAtItsEnd(Lane(n)), n - 3, 0);  // no context
  EXPECT_THROW(deltas.Build(changes, "map", stamp), std::invalid_argument);
  EXPECT_THROW(markers.Build(changes, "map", stamp), std::invalid_argument);
  // A lane new to the builder must come whole.
  VectorMapDeltaBuilder fresh;
  EXPECT_THROW(fresh.Build(Changes(Lane(n), n - 3, 18), "map", stamp), std::invalid_argument);
}

}  // namespace
}  // namespace ipm_road_mapper
