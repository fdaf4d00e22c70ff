// The publication's cost per publish: lane markers in chunks (only the changed chunks are
// re-sent), ~vector_map_delta (changes only, lanes as patches of their changed end), and
// the measurement the issue asks for: the bytes serialized per publish on a drive 3x longer
// stay those of the shorter one.
#include <gtest/gtest.h>
#include <ros/serialization.h>
#include <time.h>

#include <cmath>
#include <cstdio>
#include <set>

#include "ipm_road_mapper/ros/marker_builder.h"
#include "ipm_road_mapper/ros/vector_map_conversion.h"
#include "ipm_road_mapper/ros/vector_map_delta_builder.h"

namespace ipm_road_mapper {
namespace {

using visualization_msgs::Marker;

MapLane StraightLane(std::uint64_t id, int points, double y) {
  MapLane lane;
  lane.id = id;
  lane.class_id = 1;
  lane.class_name = "lane_white_dashed";
  lane.style = "dashed";
  for (int i = 0; i < points; ++i) lane.control_points_map.emplace_back(2.0 * i - 2.0, y, 0.0);
  lane.observations = 3;
  return lane;
}

MapMarking Arrow(std::uint64_t id, double x) {
  MapMarking m;
  m.id = id;
  m.class_id = 10;
  m.class_name = "arrow_straight";
  m.corners_map = {Eigen::Vector3d(x, -0.5, 0), Eigen::Vector3d(x + 3, -0.5, 0),
                   Eigen::Vector3d(x + 3, 0.5, 0), Eigen::Vector3d(x, 0.5, 0)};
  m.observations = 4;
  return m;
}

TEST(LaneChunks, CoverEverySegmentAndPointOnce) {
  // 40 points = 37 segments: chunks of 16, 16 and 5 segments.
  const std::vector<LaneChunk> chunks = LaneChunks(40, 16);
  ASSERT_EQ(chunks.size(), 3u);
  EXPECT_EQ(chunks[0].curve_first, 0u);
  EXPECT_EQ(chunks[0].curve_last, 19u);  // segments 0..15 use points 0..18
  EXPECT_EQ(chunks[1].curve_first, 16u);
  EXPECT_EQ(chunks[2].curve_last, 40u);
  std::size_t drawn = 0;
  for (std::size_t k = 0; k < chunks.size(); ++k) {
    EXPECT_EQ(chunks[k].index, k);
    EXPECT_EQ(chunks[k].points_first, drawn);
    drawn = chunks[k].points_last;
  }
  EXPECT_EQ(drawn, 40u);
  // No spline (< 4 points): one chunk of every point.
  ASSERT_EQ(LaneChunks(3, 16).size(), 1u);
  EXPECT_EQ(LaneChunks(3, 16)[0].points_last, 3u);
  EXPECT_NE(LaneChunkMarkerId(7, 0), LaneChunkMarkerId(7, 1));
  EXPECT_NE(LaneChunkMarkerId(7, 0), LaneChunkMarkerId(8, 0));
}

TEST(MarkerBuilder, LaneChunksJoinAndAGrowingLaneResendsItsEndOnly) {
  MarkerBuilder builder(0.5, 16);
  VectorMap map;
  map.lanes.push_back(StraightLane(3, 60, 1.7));  // 57 segments: 4 chunks
  const auto first = builder.Build(map, "map", ros::Time(1.0), MarkerBuilder::Mode::kChanges);
  std::vector<const Marker*> lines;
  for (const Marker& m : first.markers) {
    if (m.ns == "lanes") lines.push_back(&m);
  }
  ASSERT_EQ(lines.size(), 4u);
  for (std::size_t k = 1; k < lines.size(); ++k) {  // consecutive chunks share their end sample
    EXPECT_NEAR(lines[k - 1]->points.back().x, lines[k]->points.front().x, 1e-9);
  }
  EXPECT_NEAR(lines.front()->points.front().x, 0.0, 1e-9);
  EXPECT_NEAR(lines.back()->points.back().x, 2.0 * 58 - 2.0, 1e-9);  // c_58
  // The lane grows by 3 points at its end: only the last chunk (changed) and a new one, if
  // any, are sent, each as a line and its control points.
  for (int i = 60; i < 63; ++i) map.lanes[0].control_points_map.emplace_back(2.0 * i - 2.0, 1.7, 0);
  const auto grown = builder.Build(map, "map", ros::Time(2.0), MarkerBuilder::Mode::kChanges);
  std::set<int> ids;
  for (const Marker& m : grown.markers) {
    EXPECT_EQ(m.action, Marker::ADD);
    ids.insert(m.id);
  }
  EXPECT_EQ(ids, (std::set<int>{LaneChunkMarkerId(3, 3)}));
  // The lane shrinks back (a merge re-fit): the vanished chunk is deleted.
  map.lanes[0] = StraightLane(3, 40, 1.7);
  const auto shrunk = builder.Build(map, "map", ros::Time(3.0), MarkerBuilder::Mode::kChanges);
  std::set<int> deleted;
  for (const Marker& m : shrunk.markers) {
    if (m.action == Marker::DELETE) deleted.insert(m.id);
  }
  EXPECT_EQ(deleted, (std::set<int>{LaneChunkMarkerId(3, 3)}));
}

void ExpectSameMap(const VectorMap& a, const VectorMap& b) {
  ASSERT_EQ(a.markings.size(), b.markings.size());
  ASSERT_EQ(a.lanes.size(), b.lanes.size());
  for (const MapMarking& m : a.markings) {
    const auto it = std::find_if(b.markings.begin(), b.markings.end(),
                                 [&](const MapMarking& x) { return x.id == m.id; });
    ASSERT_NE(it, b.markings.end()) << m.id;
    for (int i = 0; i < 4; ++i) EXPECT_TRUE(it->corners_map[i].isApprox(m.corners_map[i]));
    EXPECT_EQ(it->observations, m.observations);
  }
  for (const MapLane& l : a.lanes) {
    const auto it = std::find_if(b.lanes.begin(), b.lanes.end(),
                                 [&](const MapLane& x) { return x.id == l.id; });
    ASSERT_NE(it, b.lanes.end()) << l.id;
    ASSERT_EQ(it->control_points_map.size(), l.control_points_map.size()) << l.id;
    for (std::size_t i = 0; i < l.control_points_map.size(); ++i) {
      EXPECT_TRUE(it->control_points_map[i].isApprox(l.control_points_map[i])) << l.id << " " << i;
    }
    EXPECT_EQ(it->style, l.style);
    EXPECT_EQ(it->observations, l.observations);
    EXPECT_EQ(it->predecessors, l.predecessors) << l.id;
    EXPECT_EQ(it->successors, l.successors) << l.id;
    EXPECT_EQ(it->unmeasured, l.unmeasured) << l.id;
  }
}

TEST(MarkerBuilder, ALaneStretchNoPixelMeasuredIsDrawnGrey) {
  MarkerBuilder builder(0.5, 16);
  VectorMap map;
  map.lanes.push_back(StraightLane(3, 20, 1.7));  // x = -2 .. 36: chunks of 16 and 1 segments
  map.lanes.push_back(StraightLane(4, 20, -1.7));
  map.lanes[0].unmeasured = {{8, 9}};  // x 14 and 16: the curve from x 12 to 18 is laid
  const auto out = builder.Build(map, "map", ros::Time(1.0), MarkerBuilder::Mode::kChanges);
  int lines = 0;
  for (const Marker& m : out.markers) {
    if (m.ns != "lanes") continue;
    ++lines;
    if (m.id != LaneChunkMarkerId(3, 0)) {
      EXPECT_TRUE(m.colors.empty());  // measured throughout: the line's one colour
      continue;
    }
    ASSERT_EQ(m.colors.size(), m.points.size());
    for (std::size_t i = 0; i < m.points.size(); ++i) {
      const double x = m.points[i].x;
      const bool grey = m.colors[i].r == m.colors[i].g && m.colors[i].a < 1.0f;
      if (x > 12.1 && x < 17.9) {
        EXPECT_TRUE(grey) << x;
      }
      if (x < 11.9 || x > 18.1) {
        EXPECT_FALSE(grey) << x;
        EXPECT_EQ(m.colors[i].a, m.color.a) << x;
      }
    }
  }
  EXPECT_EQ(lines, 4);
}

TEST(VectorMapDelta, AClientRebuildsTheMapFromTheDeltas) {
  VectorMapDeltaBuilder builder(16);
  VectorMap map;
  map.lanes.push_back(StraightLane(1, 50, 1.7));
  map.lanes.push_back(StraightLane(2, 50, -1.7));
  for (int i = 0; i < 5; ++i) map.markings.push_back(Arrow(100 + i, 10.0 * i));
  VectorMap client;
  auto delta = builder.Build(map, "map", ros::Time(1.0));
  EXPECT_EQ(delta.sequence, 1u);
  EXPECT_EQ(delta.lanes.size(), 2u);
  EXPECT_EQ(delta.lanes[0].first_index, 0u);
  ApplyVectorMapDelta(delta, &client);
  ExpectSameMap(map, client);
  // Nothing changed: an empty delta.
  delta = builder.Build(map, "map", ros::Time(2.0));
  EXPECT_TRUE(delta.markings.empty() && delta.lanes.empty() && delta.removed_lane_ids.empty());
  // Lane 1 grows and is refined near its end, lane 2 only gains an observation, a marking
  // moves, one is merged away, one is new.
  map.lanes[0].control_points_map[45].y() += 0.05;
  map.lanes[0].control_points_map.emplace_back(100.0, 1.7, 0.0);
  map.lanes[1].observations += 1;
  map.markings[1].corners_map[0].x() += 0.1;
  map.markings.erase(map.markings.begin() + 3);
  map.markings.push_back(Arrow(200, 60.0));
  delta = builder.Build(map, "map", ros::Time(3.0));
  ASSERT_EQ(delta.lanes.size(), 2u);
  EXPECT_EQ(delta.lanes[0].first_index, 32u);  // chunks of 16: the third one changed
  EXPECT_EQ(delta.lanes[0].control_points.size(), 51u - 32u);
  EXPECT_EQ(delta.lanes[1].first_index, 50u);  // no point changed, only the count
  EXPECT_TRUE(delta.lanes[1].control_points.empty());
  EXPECT_EQ(delta.markings.size(), 2u);
  EXPECT_EQ(delta.removed_marking_ids, (std::vector<std::uint64_t>{103}));
  ApplyVectorMapDelta(delta, &client);
  ExpectSameMap(map, client);
  // Only the topology changes (lane 2 continues lane 1): both lanes are sent, no point.
  map.lanes[0].successors = {2};
  map.lanes[1].predecessors = {1};
  delta = builder.Build(map, "map", ros::Time(3.5));
  ASSERT_EQ(delta.lanes.size(), 2u);
  EXPECT_TRUE(delta.lanes[0].control_points.empty());
  EXPECT_EQ(delta.lanes[0].successors, (std::vector<std::uint64_t>{2}));
  EXPECT_EQ(delta.lanes[1].predecessors, (std::vector<std::uint64_t>{1}));
  ApplyVectorMapDelta(delta, &client);
  ExpectSameMap(map, client);
  // A join lays lane 1's points 40-44 across a gap (unmeasured), then lane 1 grows on: the
  // patches carry the flags of their points, the client keeps those before them.
  for (std::size_t i = 40; i <= 44; ++i) map.lanes[0].control_points_map[i].y() += 0.02;
  map.lanes[0].unmeasured = {{40, 44}};
  delta = builder.Build(map, "map", ros::Time(3.6));
  ASSERT_EQ(delta.lanes.size(), 1u);
  EXPECT_EQ(delta.lanes[0].first_index, 32u);
  ASSERT_EQ(delta.lanes[0].unmeasured.size(), delta.lanes[0].control_points.size());
  EXPECT_EQ(delta.lanes[0].unmeasured[8], 1);
  EXPECT_EQ(delta.lanes[0].unmeasured[7], 0);
  ApplyVectorMapDelta(delta, &client);
  ExpectSameMap(map, client);
  map.lanes[0].control_points_map.emplace_back(103.0, 1.7, 0.0);
  map.lanes[0].control_points_map[49].y() += 0.01;
  delta = builder.Build(map, "map", ros::Time(3.7));
  ASSERT_EQ(delta.lanes.size(), 1u);
  EXPECT_EQ(delta.lanes[0].first_index, 48u);
  EXPECT_TRUE(delta.lanes[0].unmeasured.empty());  // none of its points
  ApplyVectorMapDelta(delta, &client);
  ExpectSameMap(map, client);
  // A lane shrinks (re-fit) and another leaves the map.
  map.lanes[0].unmeasured.clear();
  map.lanes[0].control_points_map.resize(30);
  map.lanes.erase(map.lanes.begin() + 1);
  delta = builder.Build(map, "map", ros::Time(4.0));
  EXPECT_EQ(delta.removed_lane_ids, (std::vector<std::uint64_t>{2}));
  ApplyVectorMapDelta(delta, &client);
  ExpectSameMap(map, client);
  // Applying a delta twice (it was also in a full ~vector_map) changes nothing.
  ApplyVectorMapDelta(delta, &client);
  ExpectSameMap(map, client);
  // ~reset.
  delta = builder.Clear("map", ros::Time(5.0));
  EXPECT_TRUE(delta.reset);
  EXPECT_EQ(delta.sequence, 8u);  // seven deltas before it (the topology and flag ones included)
  ApplyVectorMapDelta(delta, &client);
  EXPECT_TRUE(client.markings.empty() && client.lanes.empty());
}

// A drive along a straight road, as the nodelet publishes it: every publish the vehicle is
// 5 m further, both lanes grow by 2.5 control points on average, a marking is added every
// 20 m, and the window solve moves what lies within 40 m behind the vehicle.
struct PublishCost {
  double bytes = 0.0, markers = 0.0, delta_elements = 0.0, full_bytes = 0.0;
  double cpu_ms = 0.0;  // building the three messages (thread CPU; printed, not asserted)
};

double ThreadCpuMs() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return 1e3 * static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_nsec);
}

PublishCost MeasureDrive(double length_m, int path_max_poses) {
  MarkerBuilder markers(0.5, 16);
  VectorMapDeltaBuilder deltas(16);
  VectorMap map;
  map.lanes.push_back(StraightLane(1, 4, 1.7));
  map.lanes.push_back(StraightLane(2, 4, -1.7));
  constexpr double kStepM = 5.0, kWindowM = 40.0;
  constexpr int kMeasured = 20;  // the last publishes of the drive
  PublishCost cost;
  const int publishes = static_cast<int>(length_m / kStepM);
  std::uint64_t next_marking = 1000;
  for (int p = 0; p < publishes; ++p) {
    const double x = kStepM * (p + 1);
    for (MapLane& lane : map.lanes) {
      while (lane.control_points_map.back().x() < x) {
        lane.control_points_map.push_back(lane.control_points_map.back() +
                                          Eigen::Vector3d(2.0, 0.0, 0.0));
      }
      for (Eigen::Vector3d& c : lane.control_points_map) {  // the window solve's correction
        if (c.x() > x - kWindowM) c.z() = 0.001 * std::sin(0.1 * c.x() + p);
      }
      lane.observations += 1;
    }
    if (p % 4 == 0) map.markings.push_back(Arrow(next_marking++, x));
    for (MapMarking& m : map.markings) {
      if (m.corners_map[0].x() > x - kWindowM) m.corners_map[0].z() = 0.001 * (p % 7);
    }
    StampedPose pose;
    pose.stamp = 0.25 * p;
    pose.T_map_base.translation() = Eigen::Vector3d(x, 0, 0);
    map.trajectory.push_back(pose);
    const double cpu_start_ms = ThreadCpuMs();
    const auto marker_msg =
        markers.Build(map, "map", ros::Time(1.0), MarkerBuilder::Mode::kChanges);
    const auto delta = deltas.Build(map, "map", ros::Time(1.0));
    const auto path = ToPathMsg(map.trajectory, "map", path_max_poses, ros::Time(1.0));
    const double cpu_ms = ThreadCpuMs() - cpu_start_ms;
    if (p < publishes - kMeasured) continue;
    cost.cpu_ms += cpu_ms;
    cost.bytes += ros::serialization::serializationLength(marker_msg) +
                  ros::serialization::serializationLength(delta) +
                  ros::serialization::serializationLength(path);
    cost.markers += marker_msg.markers.size();
    cost.delta_elements += delta.markings.size() + delta.lanes.size();
    cost.full_bytes +=
        ros::serialization::serializationLength(ToVectorMapMsg(map, "map", ros::Time(1.0)));
  }
  cost.bytes /= kMeasured;
  cost.markers /= kMeasured;
  cost.delta_elements /= kMeasured;
  cost.full_bytes /= kMeasured;
  cost.cpu_ms /= kMeasured;
  return cost;
}

TEST(PublicationCost, PerPublishWorkDoesNotGrowWithTheMap) {
  // Paths of at most 100 poses: both drives are longer, as a 10 km drive is than 5000 poses.
  const PublishCost short_drive = MeasureDrive(1000.0, 100);
  const PublishCost long_drive = MeasureDrive(3000.0, 100);
  std::printf(
      "per publish, 1 km -> 3 km: %.0f -> %.0f bytes, %.1f -> %.1f markers, %.1f -> %.1f delta "
      "elements, %.3f -> %.3f ms CPU; a full ~vector_map %.0f -> %.0f bytes\n",
      short_drive.bytes, long_drive.bytes, short_drive.markers, long_drive.markers,
      short_drive.delta_elements, long_drive.delta_elements, short_drive.cpu_ms, long_drive.cpu_ms,
      short_drive.full_bytes, long_drive.full_bytes);
  // The full map triples (the check that the drives differ), a publish does not grow.
  EXPECT_GT(long_drive.full_bytes, 2.5 * short_drive.full_bytes);
  EXPECT_LT(long_drive.bytes, 1.2 * short_drive.bytes);
  EXPECT_LT(long_drive.markers, 1.2 * short_drive.markers);
  EXPECT_LT(long_drive.delta_elements, 1.2 * short_drive.delta_elements);
}

}  // namespace
}  // namespace ipm_road_mapper
