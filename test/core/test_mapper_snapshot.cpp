// Mapper::ExportSnapshot (the nodelet's live snapshot in shared storage) gives what ExportMap
// gives, on a scripted drive with the back end solving windows: arrows mapped, retired, moved
// by results, re-observed on the way back (revived: the last retired marking moves into the
// freed slot), moved again by the final solve, then a reset; and the chunks and lanes that
// did not change are the previous snapshot's (shared, not copied), as are the point chunks of
// a lane before the first point that changed.
#include <gtest/gtest.h>

#include <cmath>

#include "common/road_scene.h"
#include "ipm_road_mapper/core/map/shared_vector_map.h"
#include "ipm_road_mapper/core/mapper/mapper.h"

namespace ipm_road_mapper {
namespace {

using namespace test;  // NOLINT: the scene's helpers

constexpr int kForwardFrames = 165;  // 0 -> 132 m, then back to 0 m

// The vehicle's pose at frame k: along +x at 0.8 m a frame, then back along -x.
Eigen::Isometry3d ScriptPose(int k) {
  if (k < kForwardFrames) return PoseAt(0.8 * k);
  Eigen::Isometry3d T = PoseAt(0.8 * (2 * kForwardFrames - 1 - k));
  T.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return T;
}

// Frame k: arrows at 20, 30, ..., 110 m, a dashed lane at y = 1.8 m, all seen within 35 m
// ahead of the vehicle.
FrameInput ScriptFrame(int k) {
  FrameInput in;
  in.stamp = 100.0 + 0.1 * k;
  in.camera = TestCamera();
  in.T_map_base_odom = ScriptPose(k);
  in.mask = cv::Mat::zeros(720, 1280, CV_16UC1);
  const double x_vehicle = in.T_map_base_odom.translation().x();
  const double heading = in.T_map_base_odom.linear()(0, 0);  // +1 forward, -1 back
  auto ahead = [&](double x, double near_m) {
    const double d = heading * (x - x_vehicle);
    return d > near_m && d < 35.0;
  };
  for (double x = 0.0; x < 160.0; x += 6.0) {
    if (ahead(x, 4.0) && ahead(x + 3.0, 4.0)) {
      FillGround(Rect(x, x + 3.0, 1.725, 1.875), in.T_map_base_odom, 2001, &in.mask);
    }
  }
  int instance = 1;
  for (double x0 = 20.0; x0 <= 110.0; x0 += 10.0, ++instance) {
    if (ahead(x0, 6.0) && ahead(x0 + 3.0, 6.0) && heading * (x0 - x_vehicle) < 28.0) {
      FillGround(Rect(x0, x0 + 3.0, -0.3, 0.3), in.T_map_base_odom, 10000 + instance, &in.mask);
    }
  }
  return in;
}

// The export ExportSnapshot stands for.
nlohmann::json Expected(const Mapper& mapper, std::size_t max_poses) {
  ExportOptions options;
  options.max_trajectory_poses = max_poses;
  options.lane_topology = false;
  return VectorMapToJson(mapper.ExportMap(options));
}

TEST(MapperSnapshot, EqualsExportMapAndSharesWhatDidNotChange) {
  MapperOptions options;
  options.backend.synchronous = true;
  options.lanes.join.enabled = true;
  Mapper mapper(options, TestClasses(), TestExtrinsic());
  SnapshotCache cache(/*retired_chunk_slots=*/2, /*lane_chunk_points=*/4);
  SharedVectorMap previous;
  std::size_t revivals = 0, shared_chunks = 0, shared_lanes = 0, max_retired = 0;
  // Lanes rebuilt that kept some of their point chunks, and the points they did not copy.
  std::size_t partly_rebuilt = 0, points_not_copied = 0;
  auto check = [&](const std::string& when) {
    SCOPED_TRACE(when);
    const SharedVectorMap snapshot = mapper.ExportSnapshot(5, &cache);
    ASSERT_EQ(VectorMapToJson(snapshot.ToVectorMap()), Expected(mapper, 5));
    EXPECT_TRUE(snapshot.header.markings.empty());
    EXPECT_TRUE(snapshot.header.lanes.empty());
    // A chunk not rebuilt is the previous snapshot's own (the first chunk is the live one).
    for (std::size_t k = 1; k < snapshot.marking_chunks.size(); ++k) {
      for (std::size_t j = 1; j < previous.marking_chunks.size(); ++j) {
        shared_chunks += snapshot.marking_chunks[k] == previous.marking_chunks[j];
      }
    }
    std::size_t lane_points = 0;
    for (const auto& lane : snapshot.lanes) {
      lane_points += lane->PointCount();
      for (const auto& old : previous.lanes) {
        shared_lanes += lane == old;
        if (lane == old || lane->fields.id != old->fields.id) continue;
        // A rebuilt lane: its leading chunks may be the previous export's own.
        std::size_t kept = 0;
        while (kept < lane->point_chunks.size() && kept < old->point_chunks.size() &&
               lane->point_chunks[kept] == old->point_chunks[kept]) {
          ++kept;
        }
        if (kept > 0) {
          ++partly_rebuilt;
          points_not_copied += 4 * kept;
        }
      }
    }
    EXPECT_LE(cache.lane_points_built, lane_points);
    EXPECT_LE(cache.chunks_built, snapshot.marking_chunks.size() - 1);
    previous = snapshot;
  };
  std::size_t retired_before = 0;
  for (int k = 0; k < 2 * kForwardFrames; ++k) {
    mapper.ProcessFrame(ScriptFrame(k));
    const std::size_t retired = mapper.map().retired_markings.size();
    if (retired < retired_before) ++revivals;
    retired_before = retired;
    max_retired = std::max(max_retired, retired);
    check("frame " + std::to_string(k));
  }
  mapper.Finish();
  check("after Finish");
  // The script covered what it is for: several chunks, revivals, sharing.
  EXPECT_GE(max_retired, 6u);
  EXPECT_GT(revivals, 0u);
  EXPECT_GT(shared_chunks, 20u);
  EXPECT_GT(shared_lanes, 0u);
  // The lane grew and moved near its end while its start stood: its start was not copied.
  EXPECT_GT(partly_rebuilt, 10u);
  EXPECT_GT(points_not_copied, 100u);
  mapper.Reset();
  const SharedVectorMap empty = mapper.ExportSnapshot(5, &cache);
  EXPECT_EQ(VectorMapToJson(empty.ToVectorMap()), Expected(mapper, 5));
  EXPECT_EQ(empty.MarkingCount(), 0u);
}

TEST(MapperSnapshot, ACacheOfAnotherMapperStartsOver) {
  MapperOptions options;
  options.backend.synchronous = true;
  Mapper a(options, TestClasses(), TestExtrinsic());
  SnapshotCache cache(2);
  for (int k = 0; k < 120; ++k) {
    a.ProcessFrame(ScriptFrame(k));
    a.ExportSnapshot(0, &cache);
  }
  ASSERT_GT(a.map().retired_markings.size(), 2u);
  // A cache of a map with a later revision than this one's: rebuilt whole.
  Mapper b(options, TestClasses(), TestExtrinsic());
  for (int k = 0; k < 60; ++k) b.ProcessFrame(ScriptFrame(k));
  ASSERT_LT(b.revision(), cache.revision);
  EXPECT_EQ(VectorMapToJson(b.ExportSnapshot(0, &cache).ToVectorMap()), Expected(b, 0));
}

TEST(SharedVectorMap, ShareAndCopyBackGiveTheSameMap) {
  VectorMap map;
  map.frame_id = "world";
  MapMarking marking;
  marking.id = 7;
  marking.class_name = "arrow";
  map.markings = {marking, marking};
  map.markings[1].id = 8;
  MapLane lane;
  lane.id = 9;
  lane.control_points_map.assign(4, Eigen::Vector3d(1.0, 2.0, 3.0));
  map.lanes = {lane};
  map.trajectory = {{1.0, Eigen::Isometry3d::Identity()}};
  const SharedVectorMap shared = ShareVectorMap(map);
  EXPECT_TRUE(shared.header.markings.empty());
  EXPECT_EQ(shared.MarkingCount(), 2u);
  EXPECT_EQ(VectorMapToJson(shared.ToVectorMap()), VectorMapToJson(map));
  EXPECT_EQ(ShareVectorMap(VectorMap()).MarkingCount(), 0u);
}

}  // namespace
}  // namespace ipm_road_mapper
