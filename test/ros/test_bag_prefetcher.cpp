// BagPrefetcher: every mask, odometry and camera_info message in bag order with the right
// payload, other topics (and camera_info when not asked for) left out, a message that does not
// deserialize handed on as null, a queue far smaller than the bag, and a consumer that stops early
// (the reader is joined without a hang).
#include <gtest/gtest.h>
#include <rosbag/bag.h>
#include <std_msgs/String.h>
#include <stdlib.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "ipm_road_mapper/ros/bag_prefetcher.h"
#include "ros/bag_test_damage.h"

namespace ipm_road_mapper {
namespace {

class BagPrefetcherTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ros::Time::init();
    char pattern[] = "/tmp/irm_prefetch_XXXXXX.bag";
    const int fd = mkstemps(pattern, 4);
    ASSERT_GE(fd, 0);
    close(fd);
    path_ = pattern;
    rosbag::Bag bag(path_, rosbag::bagmode::Write);
    bag.setCompression(rosbag::compression::LZ4);
    for (int k = 0; k < 100; ++k) {
      const ros::Time t(1000.0 + 0.05 * k);
      nav_msgs::Odometry odom;
      odom.header.stamp = t;
      odom.pose.pose.position.x = k;
      bag.write("/odom", t, odom);
      sensor_msgs::Image mask;
      mask.header.stamp = t;
      mask.height = 4;
      mask.width = 8;
      mask.encoding = "16UC1";
      mask.step = 16;
      mask.data.assign(64, static_cast<std::uint8_t>(k));
      bag.write("/camera/instances", t, mask);
      if (k % 2 == 0) {
        sensor_msgs::CameraInfo info;
        info.header.stamp = t;
        info.width = 8 + k;
        bag.write("/camera/camera_info", t + ros::Duration(0.001), info);  // after its mask
      }
      std_msgs::String other;
      other.data = "not read";
      bag.write("/other", t, other);
    }
    // A wrong type on each topic (rosbag writes it under the topic's first connection, so it
    // claims to be an Image / Odometry and does not deserialize).
    std_msgs::String wrong;
    bag.write("/camera/instances", ros::Time(1010.0), wrong);
    bag.write("/odom", ros::Time(1010.0), wrong);
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

TEST_F(BagPrefetcherTest, DeliversMasksAndOdometryInBagOrder) {
  BagPrefetcher prefetcher(bag_, {"/camera/instances", "/odom", ""}, 3);
  BagPrefetcher::Item item;
  int masks = 0, odometry = 0, nulls = 0;
  double last_stamp = 0.0;
  while (prefetcher.Next(&item)) {
    ASSERT_NE(item.kind, BagPrefetcher::Kind::kCameraInfo) << "camera_info was not asked for";
    const bool is_mask = item.kind == BagPrefetcher::Kind::kMask;
    if (is_mask ? !item.mask : !item.odometry) {
      ++nulls;
      continue;
    }
    const double stamp =
        is_mask ? item.mask->header.stamp.toSec() : item.odometry->header.stamp.toSec();
    EXPECT_GE(stamp, last_stamp);
    last_stamp = stamp;
    if (is_mask) {
      ASSERT_EQ(item.mask->data.size(), 64u);
      EXPECT_EQ(item.mask->data[10], masks);
      ++masks;
    } else {
      EXPECT_DOUBLE_EQ(item.odometry->pose.pose.position.x, odometry);
      ++odometry;
    }
  }
  EXPECT_EQ(masks, 100);
  EXPECT_EQ(odometry, 100);
  EXPECT_EQ(nulls, 2);
  EXPECT_FALSE(prefetcher.Next(&item));  // stays at the end
}

TEST_F(BagPrefetcherTest, DeliversCameraInfoInBagOrderWhenAskedFor) {
  BagPrefetcher prefetcher(bag_, {"/camera/instances", "/odom", "/camera/camera_info"}, 3);
  BagPrefetcher::Item item;
  int masks = 0, odometry = 0, camera_infos = 0;
  while (prefetcher.Next(&item)) {
    masks += item.kind == BagPrefetcher::Kind::kMask && item.mask;
    odometry += item.kind == BagPrefetcher::Kind::kOdometry && item.odometry;
    if (item.kind != BagPrefetcher::Kind::kCameraInfo) continue;
    ASSERT_TRUE(item.camera_info);
    EXPECT_FALSE(item.mask || item.odometry);
    // Every second frame has one, written right after its mask.
    EXPECT_EQ(masks, 2 * camera_infos + 1);
    EXPECT_EQ(item.camera_info->width, 8u + 2 * camera_infos);
    ++camera_infos;
  }
  EXPECT_EQ(masks, 100);
  EXPECT_EQ(odometry, 100);
  EXPECT_EQ(camera_infos, 50);
}

TEST_F(BagPrefetcherTest, StopsCleanlyWhenTheConsumerLeavesEarly) {
  for (int repeat = 0; repeat < 20; ++repeat) {
    BagPrefetcher prefetcher(bag_, {"/camera/instances", "/odom", "/camera/camera_info"}, 2);
    BagPrefetcher::Item item;
    ASSERT_TRUE(prefetcher.Next(&item));
  }  // each destructor joins a reader blocked on the full queue
}

// A bag whose first chunk holds all the odometry (written first) and each later chunk one
// mask of incompressible bytes and a camera_info of the same record time, recorded between the
// odometry messages: read in time order, the odometry chunk is decompressed again after every
// mask chunk. One mask chunk (the 7th chunk of the file) is corrupt.
class DamagedBagPrefetcherTest : public ::testing::Test {
 protected:
  static constexpr int kFrames = 12;
  static constexpr int kCorruptChunk = 6;

  void SetUp() override {
    ros::Time::init();
    char pattern[] = "/tmp/irm_prefetch_damaged_XXXXXX.bag";
    const int fd = mkstemps(pattern, 4);
    ASSERT_GE(fd, 0);
    close(fd);
    path_ = pattern;
    {
      rosbag::Bag bag(path_, rosbag::bagmode::Write);
      bag.setCompression(rosbag::compression::LZ4);
      bag.setChunkThreshold(16 * 1024);
      for (int k = 0; k < kFrames; ++k) {
        nav_msgs::Odometry odom;
        odom.header.stamp = ros::Time(1000.0 + 0.1 * k);
        odom.pose.pose.position.x = k;
        bag.write("/odom", odom.header.stamp, odom);
      }
      std::uint32_t noise = 7;
      for (int k = 0; k < kFrames; ++k) {
        sensor_msgs::Image mask;
        mask.header.stamp = ros::Time(1000.0 + 0.1 * k + 0.05);
        mask.height = 100;
        mask.width = 100;
        mask.encoding = "16UC1";
        mask.step = 200;
        for (int p = 0; p < 20000; ++p) {
          noise = noise * 1664525u + 1013904223u;
          mask.data.push_back(static_cast<std::uint8_t>(noise >> 24));
        }
        sensor_msgs::CameraInfo info;
        info.header.stamp = mask.header.stamp;
        info.width = k;
        bag.write("/camera/camera_info", mask.header.stamp, info);
        bag.write("/camera/instances", mask.header.stamp, mask);
      }
    }
    test::CorruptChunk(path_, kCorruptChunk);
    bag_.open(path_, rosbag::bagmode::Read);
  }
  void TearDown() override {
    bag_.close();
    std::remove(path_.c_str());
  }

  std::string path_;
  rosbag::Bag bag_;
};

TEST_F(DamagedBagPrefetcherTest, GoesOnAfterAnUnreadableChunkWithoutGarbage) {
  BagPrefetcher prefetcher(bag_, {"/camera/instances", "/odom", "/camera/camera_info"}, 3);
  BagPrefetcher::Item item;
  int masks = 0, odometry = 0, unreadable_masks = 0, unreadable_infos = 0;
  std::vector<double> unreadable_times;
  std::vector<int> camera_info_frames;
  while (prefetcher.Next(&item)) {
    if (!item.read_error.empty()) {
      // Each message of the corrupt chunk once: resuming at their record time skips, per
      // topic, what was handled, whatever order the new View gives messages of equal time.
      unreadable_masks += item.kind == BagPrefetcher::Kind::kMask;
      unreadable_infos += item.kind == BagPrefetcher::Kind::kCameraInfo;
      EXPECT_FALSE(item.mask || item.camera_info);
      unreadable_times.push_back(item.bag_time_s);
      continue;
    }
    if (item.kind == BagPrefetcher::Kind::kMask) {
      ASSERT_TRUE(item.mask);
      ++masks;
      continue;
    }
    if (item.kind == BagPrefetcher::Kind::kCameraInfo) {
      ASSERT_TRUE(item.camera_info);
      camera_info_frames.push_back(static_cast<int>(item.camera_info->width));
      continue;
    }
    // The odometry after the corrupt chunk comes from the intact first chunk: the exact
    // values, not the bytes a failed decompression left in rosbag's chunk buffer.
    ASSERT_TRUE(item.odometry) << "odometry " << odometry << " did not deserialize";
    EXPECT_DOUBLE_EQ(item.odometry->pose.pose.position.x, odometry);
    EXPECT_NEAR(item.bag_time_s, 1000.0 + 0.1 * odometry, 1e-6);
    ++odometry;
  }
  EXPECT_EQ(unreadable_masks, 1);
  EXPECT_EQ(unreadable_infos, 1);
  EXPECT_EQ(masks, kFrames - 1);
  // The lost frame is one frame of a mask chunk; every other camera_info once, in order.
  ASSERT_EQ(unreadable_times.size(), 2u);
  EXPECT_DOUBLE_EQ(unreadable_times[0], unreadable_times[1]);
  const int lost_frame = static_cast<int>(std::lround((unreadable_times[0] - 1000.05) / 0.1));
  EXPECT_GT(lost_frame, 0);
  std::vector<int> expected_frames;
  for (int k = 0; k < kFrames; ++k) {
    if (k != lost_frame) expected_frames.push_back(k);
  }
  EXPECT_EQ(camera_info_frames, expected_frames);
  EXPECT_EQ(odometry, kFrames) << "every odometry message exactly once (none repeated on resume)";
}

}  // namespace
}  // namespace ipm_road_mapper
