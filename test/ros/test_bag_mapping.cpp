// MapBag on a small bag written here: every mask becomes one frame_done in bag order with
// its stamp (used or skipped), masks recorded before their camera_info wait for it, a mask
// without camera_info and one with a bad encoding are counted, and the first frame used is
// reported once.
#include <gtest/gtest.h>
#include <rosbag/bag.h>
#include <stdlib.h>
#include <unistd.h>

#include <cstdio>
#include <string>
#include <vector>

#include "ipm_road_mapper/ros/bag_mapping.h"
#include "ipm_road_mapper/ros/msg_conversion.h"

namespace ipm_road_mapper {
namespace {

constexpr double kT0 = 1700000000.0;
constexpr int kMasks = 10;
constexpr int kNoCameraInfo = 5;  // this frame has no camera_info
constexpr int kBadEncoding = 7;   // this frame's mask is rgb8

CameraIntrinsics Camera() {
  CameraIntrinsics c;
  c.width = 64;
  c.height = 48;
  c.fx = c.fy = 50.0;
  c.cx = 32.0;
  c.cy = 24.0;
  return c;
}

Eigen::Isometry3d Extrinsic() {
  Eigen::Matrix3d R;
  R << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R;
  T.translation() = Eigen::Vector3d(1.5, 0.0, 1.5);
  return T;
}

ClassTable Classes() {
  return ClassTable::Load(OptionsReader(YAML::Load(R"(
classes:
  - {id: 10, name: arrow_straight, kind: marking}
)"),
                                        ""));
}

class BagMappingTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ros::Time::init();
    char pattern[] = "/tmp/irm_bag_mapping_XXXXXX.bag";
    const int fd = mkstemps(pattern, 4);
    ASSERT_GE(fd, 0);
    close(fd);
    path_ = pattern;
    rosbag::Bag bag(path_, rosbag::bagmode::Write);
    bag.setCompression(rosbag::compression::LZ4);
    for (int i = 0; i <= 5 * (kMasks + 1); ++i) {  // 50 Hz odometry past the last mask
      nav_msgs::Odometry odom;
      odom.header.stamp = ros::Time(kT0 + 0.02 * i);
      odom.header.frame_id = "odom";
      odom.child_frame_id = "base_link";
      odom.pose.pose.position.x = 0.2 * i;
      odom.pose.pose.orientation.w = 1.0;
      bag.write("/odom", odom.header.stamp, odom);
    }
    for (int k = 0; k < kMasks; ++k) {
      const ros::Time stamp(kT0 + 0.1 * k + 0.01);
      sensor_msgs::Image mask;
      mask.header.stamp = stamp;
      mask.header.frame_id = "camera_optical";
      mask.height = 48;
      mask.width = 64;
      mask.encoding = k == kBadEncoding ? "rgb8" : "16UC1";
      mask.step = k == kBadEncoding ? 3 * 64 : 2 * 64;
      mask.data.assign(mask.step * mask.height, 0);
      // Recorded before its camera_info (bag time), so the mask waits for it.
      bag.write("/camera/instances", stamp + ros::Duration(0.03), mask);
      if (k == kNoCameraInfo) continue;
      sensor_msgs::CameraInfo info = IntrinsicsToCameraInfo(Camera());
      info.header = mask.header;
      bag.write("/camera/camera_info", stamp + ros::Duration(0.031), info);
    }
    bag.close();
    bag_.open(path_, rosbag::bagmode::Read);
  }
  void TearDown() override {
    bag_.close();
    std::remove(path_.c_str());
  }

  std::string path_;
  rosbag::Bag bag_;
};

TEST_F(BagMappingTest, EveryMaskIsOneFrameInBagOrder) {
  MapperOptions options;
  options.backend.enabled = false;
  RosOptions topics;
  topics.sync = "exact";
  MappingSession session(options, Classes());
  session.Start(Extrinsic());
  std::vector<std::size_t> frames;
  std::vector<double> stamps;
  int first_frame_reports = 0;
  std::size_t frames_before_first = 0;
  BagMappingCallbacks callbacks;
  callbacks.frame_done = [&](std::size_t frame, double stamp) {
    frames.push_back(frame);
    stamps.push_back(stamp);
  };
  callbacks.first_frame_mapped = [&] {
    ++first_frame_reports;
    frames_before_first = frames.size();
  };
  const std::size_t read = MapBag(bag_, topics, &session, callbacks);

  EXPECT_EQ(read, static_cast<std::size_t>(kMasks));
  ASSERT_EQ(frames.size(), static_cast<std::size_t>(kMasks));
  for (int k = 0; k < kMasks; ++k) {
    EXPECT_EQ(frames[k], static_cast<std::size_t>(k));
    EXPECT_NEAR(stamps[k], kT0 + 0.1 * k + 0.01, 1e-6) << k;
  }
  EXPECT_EQ(first_frame_reports, 1);
  EXPECT_EQ(frames_before_first, 1u) << "reported with the first frame, not at the end";
  const MapperCounters& counters = session.mapper()->counters();
  EXPECT_EQ(counters.frames_used, static_cast<std::uint64_t>(kMasks - 2));
  EXPECT_EQ(counters.frames_skipped.at("no_camera_info"), 1u);
  EXPECT_EQ(counters.frames_skipped.at("bad_mask_encoding"), 1u);
}

TEST_F(BagMappingTest, WorksWithoutCallbacks) {
  MapperOptions options;
  options.backend.enabled = false;
  MappingSession session(options, Classes());
  session.Start(Extrinsic());
  EXPECT_EQ(MapBag(bag_, RosOptions(), &session, {}), static_cast<std::size_t>(kMasks));
  EXPECT_EQ(session.mapper()->counters().frames_used, static_cast<std::uint64_t>(kMasks - 2));
}

}  // namespace
}  // namespace ipm_road_mapper
