// MapBag on a small bag written here: every mask becomes one frame_done in bag order with
// its stamp (used or skipped), masks recorded before their camera_info wait for it, a mask
// without camera_info and one with a bad encoding are counted, and the first frame used is
// reported once.
#include <gtest/gtest.h>
#include <rosbag/bag.h>
#include <stdlib.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "ipm_road_mapper/ros/bag_mapping.h"
#include "ipm_road_mapper/ros/msg_conversion.h"
#include "ros/bag_test_damage.h"

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
  const std::size_t read = MapBag(bag_, topics, &session, callbacks).frames_read;

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
  const BagMappingResult result = MapBag(bag_, RosOptions(), &session, {});
  EXPECT_EQ(result.frames_read, static_cast<std::size_t>(kMasks));
  EXPECT_TRUE(result.lost.empty());
  EXPECT_EQ(session.mapper()->counters().frames_used, static_cast<std::uint64_t>(kMasks - 2));
}

// A bag of kFrames masks in small LZ4 chunks (one mask each, incompressible background
// noise), with two of its chunks corrupted: a damaged bag.
class DamagedBagMappingTest : public ::testing::Test {
 protected:
  static constexpr int kFrames = 20;

  void SetUp() override {
    ros::Time::init();
    char pattern[] = "/tmp/irm_damaged_bag_XXXXXX.bag";
    const int fd = mkstemps(pattern, 4);
    ASSERT_GE(fd, 0);
    close(fd);
    path_ = pattern;
    {
      rosbag::Bag bag(path_, rosbag::bagmode::Write);
      bag.setCompression(rosbag::compression::LZ4);
      bag.setChunkThreshold(8192);  // one chunk per frame (odometry, camera_info, mask)
      std::uint32_t noise = 12345;
      for (int k = 0; k < kFrames; ++k) {
        for (int i = 0; i < 5; ++i) {  // 50 Hz odometry, recorded before the mask
          nav_msgs::Odometry odom;
          odom.header.stamp = ros::Time(kT0 + 0.1 * k + 0.02 * i);
          odom.header.frame_id = "odom";
          odom.child_frame_id = "base_link";
          odom.pose.pose.position.x = 0.2 * (5 * k + i);
          odom.pose.pose.orientation.w = 1.0;
          bag.write("/odom", odom.header.stamp, odom);
        }
        sensor_msgs::Image mask;
        mask.header.stamp = ros::Time(kT0 + 0.1 * k + 0.01);
        mask.header.frame_id = "camera_optical";
        mask.height = 48;
        mask.width = 64;
        mask.encoding = "16UC1";
        mask.step = 2 * 64;
        for (int p = 0; p < 64 * 48; ++p) {  // background values (< 1000) that do not compress
          noise = noise * 1664525u + 1013904223u;
          const std::uint16_t value = (noise >> 16) % 1000;
          mask.data.push_back(value & 0xff);
          mask.data.push_back(value >> 8);
        }
        sensor_msgs::CameraInfo info = IntrinsicsToCameraInfo(Camera());
        info.header = mask.header;
        bag.write("/camera/camera_info", mask.header.stamp, info);
        bag.write("/camera/instances", mask.header.stamp + ros::Duration(0.001), mask);
      }
    }
    test::CorruptChunk(path_, 5);
    test::CorruptChunk(path_, 12);
    bag_.open(path_, rosbag::bagmode::Read);  // the index at the end is intact
  }
  void TearDown() override {
    bag_.close();
    std::remove(path_.c_str());
  }

  std::string path_;
  rosbag::Bag bag_;
};

TEST_F(DamagedBagMappingTest, SkipsUnreadableChunksAndMapsTheRest) {
  MapperOptions options;
  options.backend.enabled = false;
  RosOptions topics;
  topics.sync = "exact";
  MappingSession session(options, Classes());
  session.Start(Extrinsic());
  std::vector<double> stamps;
  BagMappingCallbacks callbacks;
  callbacks.frame_done = [&](std::size_t, double stamp) { stamps.push_back(stamp); };
  BagMappingResult result;
  ASSERT_NO_THROW(result = MapBag(bag_, topics, &session, callbacks));

  EXPECT_EQ(result.frames_read, static_cast<std::size_t>(kFrames)) << "lost masks count too";
  EXPECT_EQ(stamps.size(), static_cast<std::size_t>(kFrames));
  ASSERT_EQ(result.lost.spans.size(), 2u) << "two corrupt chunks, apart";
  EXPECT_GE(result.lost.masks, 2u);
  EXPECT_LT(result.lost.masks, 6u);
  EXPECT_GE(result.lost.messages, result.lost.masks);
  EXPECT_FALSE(result.lost.first_error.empty());
  for (const LostSpan& span : result.lost.spans) {
    EXPECT_LE(span.begin_s, span.end_s);
    EXPECT_GE(span.begin_s, kT0);
    EXPECT_LE(span.end_s, kT0 + 0.1 * kFrames);
  }
  EXPECT_LT(result.lost.spans[0].end_s, result.lost.spans[1].begin_s);
  const MapperCounters& counters = session.mapper()->counters();
  EXPECT_EQ(counters.frames_skipped.at("unreadable_chunk"), result.lost.masks);
  EXPECT_GE(counters.frames_used, static_cast<std::uint64_t>(kFrames - 8))
      << "the frames after a corrupt chunk are mapped";
  EXPECT_EQ(counters.frames_used + counters.SkippedTotal(), static_cast<std::uint64_t>(kFrames));
}

}  // namespace
}  // namespace ipm_road_mapper
