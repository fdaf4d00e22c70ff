// The nodelet's mapping thread: inputs pushed from "callbacks" are mapped in its own thread
// and show up in the snapshots; a full queue drops the oldest and counts it by kind while
// the pusher never waits; ~reset runs as a command (and times out when the thread is
// busy); Finish returns the finished map within its deadline; Stop joins promptly.
#include <gtest/gtest.h>

#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <thread>

#include "ipm_road_mapper/ros/mapping_worker.h"

namespace ipm_road_mapper {
namespace {

using Clock = std::chrono::steady_clock;

MapperConfig Config(int queue_size = 100) {
  MapperConfig config;
  config.mapper.backend.enabled = false;
  Eigen::Matrix3d R;
  R << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R;
  T.translation() = Eigen::Vector3d(1.5, 0.0, 1.5);
  config.mapper.input.T_base_cam = T;  // no tf needed
  config.ros.publish_rate_hz = 50.0;
  config.ros.input_queue_size = queue_size;
  return config;
}

ClassTable Classes() {
  return ClassTable::Load(
      OptionsReader(YAML::Load("classes:\n  - {id: 10, name: arrow, kind: marking}\n"), ""));
}

FrameItem Frame(double stamp) {
  FrameItem frame;
  frame.stamp = stamp;
  frame.camera.width = 640;
  frame.camera.height = 480;
  frame.camera.fx = frame.camera.fy = 500.0;
  frame.camera.cx = 320.0;
  frame.camera.cy = 240.0;
  frame.mask = cv::Mat(480, 640, CV_16UC1, cv::Scalar(0));
  frame.camera_frame = "camera";
  return frame;
}

OdometryItem Odometry(double stamp) {
  OdometryItem odometry;
  odometry.pose.stamp = stamp;
  odometry.pose.T_map_base.translation() = Eigen::Vector3d(10.0 * stamp, 0.0, 0.0);
  odometry.frame_id = "odom";
  return odometry;
}

const TransformLookup kNoTf = [](const std::string&, const std::string&, Eigen::Isometry3d*) {
  return std::string("no tf in this test");
};

// Waits (bounded) until the latest snapshot satisfies `condition`.
template <typename Condition>
bool WaitForSnapshot(const MappingWorker& worker, Condition condition) {
  const auto deadline = Clock::now() + std::chrono::seconds(10);
  while (Clock::now() < deadline) {
    if (condition(*worker.Latest())) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return false;
}

void Feed(MappingWorker* worker, int frames) {
  for (int i = 0; i <= frames; ++i) {
    worker->Push(Odometry(0.1 * i));
    if (i < frames) worker->Push(Frame(0.1 * i + 0.05));
  }
}

TEST(MappingWorker, MapsInItsThreadAndPublishesSnapshots) {
  std::atomic<int> updates{0};
  MappingWorker::Hooks hooks;
  hooks.on_update = [&](const SessionUpdate& update, const FrameOutputs& outputs) {
    updates += static_cast<int>(update.used.size());
    // REP-105: the map in ros/map_frame, the odometry's frame is odom (map -> odom).
    EXPECT_EQ(outputs.map_frame, "map");
    EXPECT_EQ(outputs.odom_frame, "odom");
  };
  MappingWorker worker(Config(), Classes(), "test", kNoTf, hooks);
  EXPECT_EQ(worker.Latest()->map, nullptr);  // before the first frame
  Feed(&worker, 10);
  ASSERT_TRUE(WaitForSnapshot(
      worker, [](const MapSnapshot& s) { return s.map && s.status.counters.frames_used == 10; }));
  const auto snapshot = worker.Latest();
  EXPECT_EQ(snapshot->map->header.frame_id, "map");  // as map_from_bag's map.json
  EXPECT_EQ(snapshot->map->header.trajectory.size(), 10u);
  EXPECT_EQ(snapshot->refined_camera_frame, "camera_refined");
  EXPECT_NEAR(snapshot->newest_frame_stamp, 0.95, 1e-9);
  EXPECT_EQ(updates.load(), 10);
  EXPECT_EQ(worker.dropped(), (std::array<std::uint64_t, kInputKindCount>{}));
}

TEST(MappingWorker, FullQueueDropsTheOldestWithoutBlockingThePusher) {
  ros::Time::init();  // the throttled drop warning reads ROS time (no node in this test)
  std::mutex mutex;
  std::condition_variable released;
  bool release = false, blocked = false;
  MappingWorker::Hooks hooks;
  hooks.on_update = [&](const SessionUpdate&, const FrameOutputs&) {
    std::unique_lock<std::mutex> lock(mutex);
    blocked = true;
    released.notify_all();
    released.wait(lock, [&] { return release; });  // the mapping thread is busy
  };
  MappingWorker worker(Config(5), Classes(), "test", kNoTf, hooks);
  // Destroyed before the worker: whatever fails below, the hook is released and joined.
  struct Release {
    std::function<void()> fn;
    ~Release() { fn(); }
  } release_at_exit{[&] {
    {
      std::lock_guard<std::mutex> lock(mutex);
      release = true;
    }
    released.notify_all();
  }};
  Feed(&worker, 1);  // one used frame: the thread blocks in its hook
  {
    std::unique_lock<std::mutex> lock(mutex);
    ASSERT_TRUE(released.wait_for(lock, std::chrono::seconds(10), [&] { return blocked; }));
  }
  const auto start = Clock::now();
  for (int i = 0; i < 20; ++i) worker.Push(Odometry(1.0 + 0.1 * i));
  EXPECT_LT(Clock::now() - start, std::chrono::seconds(1));  // never waited for the mapper
  EXPECT_EQ(worker.dropped()[static_cast<std::size_t>(InputKind::kOdometry)], 15u);
  EXPECT_EQ(worker.dropped()[static_cast<std::size_t>(InputKind::kFrame)], 0u);
  // A reset cannot run while the thread is busy: the service answers failure in time.
  std::string message;
  const auto reset_start = Clock::now();
  EXPECT_FALSE(worker.Reset(0.2, &message));
  EXPECT_LT(Clock::now() - reset_start, std::chrono::seconds(2));
  EXPECT_NE(message.find("not reset"), std::string::npos) << message;
}

TEST(MappingWorker, ResetIsACommandOfTheMappingThread) {
  MappingWorker worker(Config(), Classes(), "test", kNoTf, {});
  Feed(&worker, 5);
  ASSERT_TRUE(WaitForSnapshot(
      worker, [](const MapSnapshot& s) { return s.map && s.map->header.trajectory.size() == 5; }));
  EXPECT_EQ(worker.Latest()->resets, 0u);
  std::string message;
  EXPECT_TRUE(worker.Reset(2.0, &message)) << message;
  const auto after = worker.Latest();  // swapped in before Reset returned
  ASSERT_NE(after->map, nullptr);
  EXPECT_TRUE(after->map->header.trajectory.empty());
  EXPECT_EQ(after->resets, 1u);  // the generation the saver files post-reset maps by
}

TEST(MappingWorker, FinishReturnsTheFinishedMapAndStopJoins) {
  MappingWorker worker(Config(), Classes(), "test", kNoTf, {});
  Feed(&worker, 8);
  bool finished = false;
  const auto start = Clock::now();
  const auto map = worker.Finish(start + std::chrono::seconds(3), &finished);
  EXPECT_TRUE(finished);
  ASSERT_NE(map, nullptr);
  EXPECT_EQ(map->trajectory.size(), 8u);  // what was queued was mapped first
  worker.Push(Odometry(9.0));             // after Finish: ignored
  worker.Stop();
  EXPECT_LT(Clock::now() - start, std::chrono::seconds(3 + 1));
  worker.Stop();  // idempotent
}

// A Finish whose budget the queue outlasts returns the map of every frame the thread used
// (the saved map and the final counters agree), not an older periodic snapshot, and keeps
// within its grace (the frames still queued are dropped).
TEST(MappingWorker, FinishPastTheBudgetSavesEveryFrameUsed) {
  MappingWorker worker(Config(100000), Classes(), "test", kNoTf, {});
  Feed(&worker, 1500);  // the snapshots, every 20 ms, lag the frames used
  ASSERT_TRUE(WaitForSnapshot(
      worker, [](const MapSnapshot& s) { return s.status.counters.frames_used > 0; }));
  bool finished = true;
  const auto start = Clock::now();
  const auto map = worker.Finish(start, &finished);  // the budget is gone at once
  EXPECT_LT(Clock::now() - start, MappingWorker::kFinishGrace + std::chrono::milliseconds(200));
  EXPECT_FALSE(finished);
  ASSERT_NE(map, nullptr);
  worker.Stop();
  const std::uint64_t used = worker.Latest()->status.counters.frames_used;
  EXPECT_EQ(map->trajectory.size(), used);
}

TEST(MappingWorker, SnapshotsShareTheFrozenTrajectoryAndSavesGetItWhole) {
  MapperConfig config = Config(100000);
  config.ros.path_max_poses = 10;
  config.mapper.backend.window_frames = 20;  // a solve may change the newest 200 frames
  MappingWorker worker(config, Classes(), "test", kNoTf, {});
  constexpr int kFrames = 1500;
  Feed(&worker, kFrames);
  ASSERT_TRUE(WaitForSnapshot(worker, [](const MapSnapshot& s) {
    return s.map && s.status.counters.frames_used == kFrames;
  }));
  const auto snapshot = worker.Latest();
  // 1300 frames are out of every window: one 1000-pose chunk frozen, the rest in the map.
  ASSERT_EQ(snapshot->trajectory_prefix.size(), 1u);
  EXPECT_EQ(snapshot->map->header.trajectory.size(), kFrames - 1000u);
  const auto full = snapshot->FullMap();
  ASSERT_EQ(full->trajectory.size(), static_cast<std::size_t>(kFrames));
  for (std::size_t i = 0; i < full->trajectory.size(); ++i) {
    ASSERT_NEAR(full->trajectory[i].stamp, 0.1 * static_cast<double>(i) + 0.05, 1e-9) << i;
  }
  // The finished map (the shutdown save) has every pose as well.
  bool finished = false;
  const auto finished_map = worker.Finish(Clock::now() + std::chrono::seconds(5), &finished);
  EXPECT_TRUE(finished);
  ASSERT_NE(finished_map, nullptr);
  EXPECT_EQ(finished_map->trajectory.size(), static_cast<std::size_t>(kFrames));
}

TEST(MappingWorker, FinishBeforeAnyFrameHasNoMap) {
  MappingWorker worker(Config(), Classes(), "test", kNoTf, {});
  bool finished = false;
  EXPECT_EQ(worker.Finish(Clock::now() + std::chrono::seconds(2), &finished), nullptr);
  EXPECT_TRUE(finished);
}

}  // namespace
}  // namespace ipm_road_mapper

namespace ipm_road_mapper {
namespace {

// A live snapshot's map has no lane topology (no message carries it, and linking it costs
// the lanes' count times their length on every export); the copy a save writes has it.
TEST(MapSnapshot, FullMapLinksTheLaneTopologyTheSnapshotSkips) {
  auto lane = [](std::uint64_t id, double x0) {
    MapLane l;
    l.id = id;
    l.class_id = 2;
    for (int i = -1; i <= 11; ++i) l.control_points_map.emplace_back(x0 + 2.0 * i, 0.0, 0.0);
    l.observations = 3;
    return l;
  };
  VectorMap map;
  map.lanes = {lane(1, 0.0), lane(2, 20.0)};  // 2 starts where 1 ends
  MapSnapshot snapshot;
  snapshot.map = std::make_shared<const SharedVectorMap>(ShareVectorMap(map));
  const std::shared_ptr<const VectorMap> full = snapshot.FullMap();
  ASSERT_EQ(full->lanes.size(), 2u);
  EXPECT_EQ(full->lanes[0].successors, std::vector<std::uint64_t>{2});
  EXPECT_EQ(full->lanes[1].predecessors, std::vector<std::uint64_t>{1});
  EXPECT_TRUE(
      snapshot.map->lanes[0]->fields.successors.empty());  // the snapshot's own map untouched
}

}  // namespace
}  // namespace ipm_road_mapper
