// The publication built from the core's incremental export (Mapper::ExportChanges) equals the
// one built the old way from the whole exported map, on a scripted drive of the core Mapper
// with the back end solving windows: markings created, re-observed, re-optimized, retired and
// moved by the final solve, a spurious blob dropped, an odometry jump that starts duplicate
// elements, lanes grown, and a lane that resumes after a gap in its paint as a second lane
// which is then joined into the first (its id removed). Every ~vector_map_delta is the same
// message byte for byte; every ~markers array holds the same markers (DELETEs in any order).
#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <vector>

#include "common/road_scene.h"
#include "ipm_road_mapper/core/mapper/mapper.h"
#include "ipm_road_mapper/ros/marker_builder.h"
#include "ipm_road_mapper/ros/vector_map_delta_builder.h"
#include "ros/message_bytes.h"

namespace ipm_road_mapper {
namespace {

using namespace test;  // NOLINT: the scene's helpers

// Frame k of the script: the vehicle at 0.8 k m along x (its odometry 1.2 m ahead from
// frame 45 on: duplicates), arrows at 20, 50 and 80 m, a dashed lane at y = 1.8 m with no
// paint in [72, 84) m, and at frame 12 a blob seen once.
FrameInput ScriptFrame(int k) {
  const double x_vehicle = 0.8 * k;
  FrameInput in;
  in.stamp = 100.0 + 0.1 * k;
  in.camera = TestCamera();
  const Eigen::Isometry3d T_map_base = PoseAt(x_vehicle);
  in.T_map_base_odom = PoseAt(x_vehicle + (k >= 45 ? 1.2 : 0.0));
  in.mask = cv::Mat::zeros(720, 1280, CV_16UC1);
  for (double x = 0.0; x < 160.0; x += 6.0) {
    if (x < x_vehicle + 4.0 || x > x_vehicle + 35.0 || (x >= 72.0 && x < 84.0)) continue;
    FillGround(Rect(x, x + 3.0, 1.725, 1.875), T_map_base, 2001, &in.mask);
  }
  int instance = 1;
  for (double x0 : {20.0, 50.0, 80.0}) {
    if (x_vehicle + 6.0 < x0 && x0 < x_vehicle + 28.0 && k % 9 != 4) {
      FillGround(Rect(x0, x0 + 3.0, -0.3, 0.3), T_map_base, 10000 + instance, &in.mask);
    }
    ++instance;
  }
  if (k == 12) {
    FillGround(Rect(x_vehicle + 12.0, x_vehicle + 13.0, -2.0, -1.5), T_map_base, 10009, &in.mask);
  }
  return in;
}

TEST(IncrementalPublication, EqualsThePublicationBuiltFromTheWholeMap) {
  MapperOptions options;
  options.backend.synchronous = true;
  options.lanes.join.enabled = true;
  Mapper mapper(options, TestClasses(), TestExtrinsic());
  VectorMapDeltaBuilder old_deltas, new_deltas;
  MarkerBuilder old_markers, new_markers;
  std::uint64_t revision = 0;
  std::size_t updated = 0, removed = 0, lane_patches = 0, deletes = 0;
  std::set<std::uint64_t> created;
  const ros::Time stamp(1.0);
  auto publish = [&](int k) {
    SCOPED_TRACE("frame " + std::to_string(k));
    const VectorMap map = mapper.ExportMap();
    const MapChanges changes = mapper.ExportChanges(revision);
    revision = changes.revision;
    const ipm_road_mapper::VectorMapDelta old_delta = old_deltas.Build(map, "map", stamp);
    const ipm_road_mapper::VectorMapDelta new_delta = new_deltas.Build(changes, "map", stamp);
    EXPECT_EQ(Bytes(new_delta), Bytes(old_delta))
        << new_delta.markings.size() << " vs " << old_delta.markings.size() << " markings, "
        << new_delta.lanes.size() << " vs " << old_delta.lanes.size() << " lanes, "
        << new_delta.removed_marking_ids.size() << " vs " << old_delta.removed_marking_ids.size()
        << " removed markings";
    const visualization_msgs::MarkerArray old_array =
        old_markers.Build(map, "map", stamp, MarkerBuilder::Mode::kChanges);
    const visualization_msgs::MarkerArray new_array = new_markers.Build(changes, "map", stamp);
    EXPECT_EQ(MarkerSet(new_array), MarkerSet(old_array))
        << new_array.markers.size() << " vs " << old_array.markers.size() << " markers";
    for (const auto& m : old_delta.markings) {
      if (!created.insert(m.id).second) ++updated;
    }
    removed += old_delta.removed_marking_ids.size() + old_delta.removed_lane_ids.size();
    lane_patches += old_delta.lanes.size();
    for (const auto& m : old_array.markers)
      deletes += m.action == visualization_msgs::Marker::DELETE;
    // Less than the whole map once the map has grown.
    EXPECT_LE(changes.map.markings.size(), map.markings.size());
  };
  for (int k = 0; k < 150; ++k) {
    mapper.ProcessFrame(ScriptFrame(k));
    publish(k);
  }
  mapper.Finish();
  publish(-1);
  // The script covered what it is for.
  EXPECT_GE(created.size(), 3u);
  EXPECT_GT(updated, 0u);
  EXPECT_GT(lane_patches, 0u);
  EXPECT_GT(removed, 0u);
  EXPECT_GT(deletes, 0u);
  EXPECT_GT(mapper.map().retired_markings.size(), 0u);
  EXPECT_GT(mapper.counters().markings_merged + mapper.counters().lanes_merged +
                mapper.counters().lanes_joined,
            0u);
  std::printf("script: %zu created, %zu updated, %zu removed, %zu lane patches, %zu DELETEs\n",
              created.size(), updated, removed, lane_patches, deletes);
}

// Frame k of a 400 m drive at 2 m a frame: the script's dashed lane and an arrow every 50 m
// (missed now and then), the odometry 1.2 m ahead from frame 120 on (duplicates).
FrameInput LongFrame(int k) {
  const double x_vehicle = 2.0 * k;
  FrameInput in;
  in.stamp = 100.0 + 0.1 * k;
  in.camera = TestCamera();
  const Eigen::Isometry3d T_map_base = PoseAt(x_vehicle);
  in.T_map_base_odom = PoseAt(x_vehicle + (k >= 120 ? 1.2 : 0.0));
  in.mask = cv::Mat::zeros(720, 1280, CV_16UC1);
  for (double x = 0.0; x < 440.0; x += 6.0) {
    if (x < x_vehicle + 4.0 || x > x_vehicle + 35.0) continue;
    FillGround(Rect(x, x + 3.0, 1.725, 1.875), T_map_base, 2001, &in.mask);
  }
  int instance = 1;
  for (double x0 = 20.0; x0 < 420.0; x0 += 50.0, ++instance) {
    if (x_vehicle + 6.0 < x0 && x0 < x_vehicle + 28.0 && k % 9 != 4) {
      FillGround(Rect(x0, x0 + 3.0, -0.3, 0.3), T_map_base, 10000 + instance, &in.mask);
    }
  }
  return in;
}

// A drive published as the nodelet does: the core's changes carry each changed lane's tail
// only (with the context the builders ask for), and the builders look at the chunks from the
// first changed point on; every message is still the whole-map way's. Returns how many lanes
// came as tails.
std::size_t ExpectTailsPublishAsTheWholeMap(FrameInput (*frame)(int), int frames,
                                            std::size_t chunk) {
  MapperOptions options;
  options.backend.synchronous = true;
  options.lanes.join.enabled = true;
  Mapper mapper(options, TestClasses(), TestExtrinsic());
  VectorMapDeltaBuilder old_deltas(chunk), new_deltas(chunk);
  MarkerBuilder old_markers(0.5, chunk), new_markers(0.5, chunk);
  ChangesOptions tails;
  tails.lane_context_points =
      std::max(new_deltas.lane_context_points(), new_markers.lane_context_points());
  std::uint64_t revision = 0;
  std::size_t ranged = 0;
  const ros::Time stamp(1.0);
  auto publish = [&](int k) {
    SCOPED_TRACE("frame " + std::to_string(k));
    const VectorMap map = mapper.ExportMap();
    const MapChanges changes = mapper.ExportChanges(revision, tails);
    revision = changes.revision;
    for (std::size_t offset : changes.lane_offsets) ranged += offset > 0;
    EXPECT_EQ(Bytes(new_deltas.Build(changes, "map", stamp)),
              Bytes(old_deltas.Build(map, "map", stamp)));
    EXPECT_EQ(MarkerSet(new_markers.Build(changes, "map", stamp)),
              MarkerSet(old_markers.Build(map, "map", stamp, MarkerBuilder::Mode::kChanges)));
  };
  for (int k = 0; k < frames; ++k) {
    mapper.ProcessFrame(frame(k));
    publish(k);
  }
  mapper.Finish();
  publish(-1);
  return ranged;
}

TEST(IncrementalPublication, LaneTailsGiveThePublicationBuiltFromTheWholeMap) {
  // The script (its lanes mostly within a window's reach, with short chunks), then the long
  // drive with the nodelet's chunks: there most changes come as tails.
  ExpectTailsPublishAsTheWholeMap(ScriptFrame, 150, 4);
  EXPECT_GT(ExpectTailsPublishAsTheWholeMap(LongFrame, 200, 16), 50u);
}

}  // namespace
}  // namespace ipm_road_mapper
