// The nodelet's unload after a long drive (issue 10: "unload with save_map_path after a
// 10 km drive <= ros/shutdown_budget_s + 1 s, map saved"), measured in-process: the drive's
// masks, camera_info and odometry are pushed into a MappingWorker faster than real time
// (paced so that its queue never drops), then the shutdown path runs as
// MapperNodelet::SaveAtShutdown + Stop do: Finish until the budget's deadline, the best map
// saved (SaveMapFiles), the mapping thread joined. Set IRM_LONG_BAG to a drive.bag (the
// long benchmark's, `bash scripts/benchmark.sh --long`: out/benchmark/drives/
// public_road_long/drive.bag); without it the test is skipped. Optional: IRM_LONG_FRAMES
// (stop after this many masks), IRM_LONG_OUT (where the map is saved).
#include <gtest/gtest.h>
#include <nav_msgs/Odometry.h>
#include <ros/time.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <thread>

#include "ipm_road_mapper/pipeline/map_files.h"
#include "ipm_road_mapper/ros/bag_input.h"
#include "ipm_road_mapper/ros/mapping_worker.h"
#include "ipm_road_mapper/ros/msg_conversion.h"

namespace ipm_road_mapper {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

TEST(LongDriveUnload, FinishesAndSavesWithinTheBudget) {
  const char* bag_path = std::getenv("IRM_LONG_BAG");
  if (!bag_path) GTEST_SKIP() << "set IRM_LONG_BAG=<drive.bag> (a long drive) to measure";
  ros::Time::init();  // no node here: the worker's diagnostics stamp with ros::Time::now()
  const std::size_t max_frames =
      std::getenv("IRM_LONG_FRAMES") ? std::stoul(std::getenv("IRM_LONG_FRAMES")) : 0;
  const std::string out =
      std::getenv("IRM_LONG_OUT") ? std::getenv("IRM_LONG_OUT") : "/tmp/irm_long_unload";
  MapperConfig config = LoadMapperConfigFile(IRM_SOURCE_DIR "/config/mapper.yaml");
  config.ros.input_queue_size = 100000;
  const ClassTable classes = ClassTable::LoadFile(IRM_SOURCE_DIR "/config/classes.yaml");
  rosbag::Bag bag;
  ASSERT_EQ(OpenBagForReading(bag_path, &bag), "");
  const TransformLookup lookup = [&bag](const std::string& parent, const std::string& child,
                                        Eigen::Isometry3d* T) {
    return LookupStaticTransform(bag, parent, child, T);
  };
  MappingWorker worker(config, classes, "long_unload", lookup, {});

  // Feed: masks paired with the camera_info of the same stamp, odometry as it comes; at most
  // kAhead frames ahead of the mapping thread (the snapshot counts them).
  constexpr std::uint64_t kAhead = 400;
  std::map<double, sensor_msgs::ImageConstPtr> masks;
  std::map<double, sensor_msgs::CameraInfoConstPtr> infos;
  std::uint64_t pushed = 0;
  const auto feed_start = Clock::now();
  auto push_pairs = [&] {
    for (auto it = masks.begin(); it != masks.end();) {
      const auto info = infos.find(it->first);
      if (info == infos.end()) {
        ++it;
        continue;
      }
      FrameItem frame;
      frame.stamp = it->first;
      frame.camera_frame = it->second->header.frame_id;
      EXPECT_EQ(ImageToMask(*it->second, &frame.mask), "");
      EXPECT_EQ(CameraInfoToIntrinsics(*info->second, &frame.camera), "");
      worker.Push(std::move(frame));
      ++pushed;
      infos.erase(info);
      it = masks.erase(it);
      while (true) {
        const MapperStatusSnapshot& s = worker.Latest()->status;
        std::uint64_t skipped = 0;
        for (const auto& [reason, n] : s.counters.frames_skipped) skipped += n;
        if (pushed <= s.counters.frames_used + skipped + kAhead) break;
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
      }
    }
  };
  const std::vector<std::string> topics = {config.ros.mask_topic, config.ros.camera_info_topic,
                                           config.ros.odom_topic};
  for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery(topics))) {
    if (max_frames > 0 && pushed >= max_frames) break;
    if (auto image = m.instantiate<sensor_msgs::Image>()) {
      masks[ToSeconds(image->header.stamp)] = image;
    } else if (auto info = m.instantiate<sensor_msgs::CameraInfo>()) {
      infos[ToSeconds(info->header.stamp)] = info;
    } else if (auto odom = m.instantiate<nav_msgs::Odometry>()) {
      OdometryItem item;
      item.frame_id = odom->header.frame_id;
      EXPECT_EQ(OdometryToStampedPose(*odom, &item.pose), "");
      worker.Push(std::move(item));
    }
    push_pairs();
  }
  const double feed_s = Seconds(Clock::now() - feed_start);

  // The unload: MapperNodelet::Shutdown's deadline, SaveAtShutdown, then Stop.
  const double budget_s = config.ros.shutdown_budget_s;
  const auto unload_start = Clock::now();
  const auto deadline = unload_start + std::chrono::duration_cast<Clock::duration>(
                                           std::chrono::duration<double>(budget_s));
  bool finished = false;
  const std::shared_ptr<const VectorMap> map = worker.Finish(deadline, &finished);
  const double finish_s = Seconds(Clock::now() - unload_start);
  ASSERT_NE(map, nullptr);
  std::filesystem::create_directories(out);
  SaveMapFiles(*map, config.geo_origin, MapFilePathsInFolder(out));
  const double saved_s = Seconds(Clock::now() - unload_start);
  worker.Stop();
  const double unload_s = Seconds(Clock::now() - unload_start);
  double km = 0.0;  // path length
  for (std::size_t i = 1; i < map->trajectory.size(); ++i) {
    km += 1e-3 * (map->trajectory[i].T_map_base.translation() -
                  map->trajectory[i - 1].T_map_base.translation())
                     .norm();
  }
  std::printf(
      "long drive: %lu frames pushed in %.1f s (%lu poses, %zu markings, %zu lanes, %.2f km "
      "driven); unload: Finish %.2f s (%s), saved at %.2f s, mapping thread joined at "
      "%.2f s; budget %.1f s\n",
      static_cast<unsigned long>(pushed), feed_s,
      static_cast<unsigned long>(map->trajectory.size()), map->markings.size(), map->lanes.size(),
      km, finish_s, finished ? "finished map" : "past the budget: latest snapshot", saved_s,
      unload_s, budget_s);
  EXPECT_LE(unload_s, budget_s + 1.0);
  EXPECT_EQ(map->trajectory.size(), worker.Latest()->status.counters.frames_used);
  EXPECT_TRUE(std::filesystem::exists(MapFilePathsInFolder(out).json));
}

}  // namespace
}  // namespace ipm_road_mapper
