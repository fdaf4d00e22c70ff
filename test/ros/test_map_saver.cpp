// MapSaver: the saver thread autosaves the latest snapshot when it changed, a post-reset
// smaller map goes to <stem>_reset<N>.json, failures are counted with their reason, and a
// save after Stop() (the shutdown save) still works.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <thread>

#include "ipm_road_mapper/ros/map_saver.h"

namespace ipm_road_mapper {
namespace {

namespace fs = std::filesystem;

VectorMap MapWith(int markings) {
  VectorMap map;
  for (int i = 0; i < markings; ++i) {
    MapMarking m;
    m.id = static_cast<std::uint64_t>(i + 1);
    m.class_id = 3;
    m.class_name = "arrow";
    m.corners_map = {Eigen::Vector3d(i, 0, 0), Eigen::Vector3d(i + 1, 0, 0),
                     Eigen::Vector3d(i + 1, 1, 0), Eigen::Vector3d(i, 1, 0)};
    map.markings.push_back(m);
  }
  map.trajectory.push_back(StampedPose{});
  return map;
}

// What the mapping thread would swap in; settable from the test.
class FakeWorker {
 public:
  void Set(int markings, std::uint64_t version, std::uint64_t resets) {
    auto snapshot = std::make_shared<MapSnapshot>();
    snapshot->map = std::make_shared<const SharedVectorMap>(ShareVectorMap(MapWith(markings)));
    snapshot->map_version = version;
    snapshot->resets = resets;
    std::lock_guard<std::mutex> lock(mutex_);
    latest_ = snapshot;
  }
  std::shared_ptr<const MapSnapshot> Latest() {
    std::lock_guard<std::mutex> lock(mutex_);
    return latest_;
  }

 private:
  std::mutex mutex_;
  std::shared_ptr<const MapSnapshot> latest_ = std::make_shared<const MapSnapshot>();
};

bool WaitFor(const std::function<bool()>& condition, double timeout_s = 10.0) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (std::chrono::steady_clock::now() < end) {
    if (condition()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return condition();
}

std::string Folder(const std::string& name) {
  const std::string dir = testing::TempDir() + "/irm_test_map_saver/" + name;
  fs::remove_all(dir);
  return dir;
}

TEST(MapSaver, AutosavesChangesAndKeepsThePreResetMap) {
  const std::string dir = Folder("autosave");
  FakeWorker worker;
  MapSaver saver(
      dir + "/live.json", std::nullopt, 0.05, "test", [&] { return worker.Latest(); }, nullptr);
  // Nothing before the first map.
  std::this_thread::sleep_for(std::chrono::milliseconds(150));
  EXPECT_EQ(saver.status().saves, 0u);

  worker.Set(3, 1, 0);
  ASSERT_TRUE(WaitFor([&] { return saver.status().saves >= 1; }));
  EXPECT_EQ(LoadVectorMapJson(dir + "/live.json").markings.size(), 3u);
  EXPECT_TRUE(fs::exists(dir + "/live_trajectory_tum.txt"));
  const MapSaveStatus first = saver.status();
  EXPECT_TRUE(first.last_ok);
  EXPECT_GT(first.last_wall_time, 0.0);
  EXPECT_NE(first.last_status.find("ok: 3 markings, 0 lanes to " + dir + "/live.json"),
            std::string::npos)
      << first.last_status;
  // Unchanged snapshot: no new save.
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  EXPECT_EQ(saver.status().saves, first.saves);

  // ~reset: the smaller map goes apart, the saved map stays.
  worker.Set(1, 2, 1);
  ASSERT_TRUE(WaitFor([&] { return fs::exists(dir + "/live_reset1.json"); }));
  EXPECT_EQ(LoadVectorMapJson(dir + "/live_reset1.json").markings.size(), 1u);
  EXPECT_FALSE(fs::exists(dir + "/live_reset1.geojson")) << "no GeoJSON without a geo origin";
  EXPECT_TRUE(fs::exists(dir + "/live_reset1_trajectory_tum.txt"));
  EXPECT_EQ(LoadVectorMapJson(dir + "/live.json").markings.size(), 3u);

  // The shutdown save, after the thread stopped, follows the post-reset map.
  saver.Stop();
  const MapSaveResult final_save = saver.Save(MapWith(5), 1);
  EXPECT_TRUE(final_save.ok) << final_save.message;
  EXPECT_TRUE(final_save.diverted);
  EXPECT_EQ(LoadVectorMapJson(dir + "/live_reset1.json").markings.size(), 5u);
  EXPECT_EQ(LoadVectorMapJson(dir + "/live.json").markings.size(), 3u);
}

TEST(MapSaver, AFailedSaveIsCountedWithItsReason) {
  const std::string dir = Folder("unwritable");
  fs::create_directories(dir);
  std::ofstream(dir + "/file") << "x";
  FakeWorker worker;
  worker.Set(2, 1, 0);
  MapSaver saver(
      dir + "/file/live.json", std::nullopt, 0.05, "test", [&] { return worker.Latest(); },
      nullptr);
  ASSERT_TRUE(WaitFor([&] { return saver.status().failures >= 1; }));
  const MapSaveStatus status = saver.status();
  EXPECT_FALSE(status.last_ok);
  EXPECT_NE(status.last_status.find(dir + "/file"), std::string::npos) << status.last_status;
  const MapSaveResult result = saver.Save(MapWith(2), 0);
  EXPECT_FALSE(result.ok);
  EXPECT_EQ(result.paths.json, dir + "/file/live.json");
}

TEST(MapSaver, PeriodZeroNeverAutosaves) {
  const std::string dir = Folder("off");
  FakeWorker worker;
  worker.Set(2, 1, 0);
  {
    MapSaver saver(
        dir + "/live.json", std::nullopt, 0.0, "test", [&] { return worker.Latest(); }, nullptr);
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    EXPECT_EQ(saver.status().saves, 0u);
  }  // the destructor stops and joins the thread
  EXPECT_FALSE(fs::exists(dir + "/live.json"));
}

}  // namespace
}  // namespace ipm_road_mapper
