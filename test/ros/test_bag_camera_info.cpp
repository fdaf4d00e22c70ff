// camera_info <-> mask pairing while a bag is streamed: exact by ros::Time, approximate
// within half the period of the first camera_infos (only those are read), a bag loop and
// old entries dropped from the table, and masks held until their camera_info is read, in
// order, bounded, and decided at the end.
#include <gtest/gtest.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <stdlib.h>
#include <unistd.h>

#include <cstdio>
#include <string>
#include <vector>

#include "ipm_road_mapper/ros/bag_camera_info.h"
#include "ipm_road_mapper/ros/msg_conversion.h"

namespace ipm_road_mapper {
namespace {

constexpr double kT0 = 1700000000.0;  // epoch stamps: doubles are too coarse for "exact"
constexpr const char* kTopic = "/camera/camera_info";

CameraIntrinsics MakeIntrinsics(int width = 640) {
  CameraIntrinsics intrinsics;
  intrinsics.width = width;
  intrinsics.height = 480;
  intrinsics.fx = intrinsics.fy = 500.0;
  intrinsics.cx = 320.0;
  intrinsics.cy = 240.0;
  return intrinsics;
}

sensor_msgs::CameraInfo MakeInfo(double t_s, int width = 640) {
  sensor_msgs::CameraInfo info = IntrinsicsToCameraInfo(MakeIntrinsics(width));
  info.header.stamp = ros::Time(kT0) + ros::Duration(t_s);
  return info;
}

sensor_msgs::Image::ConstPtr MakeMask(double t_s) {
  auto mask = boost::make_shared<sensor_msgs::Image>();
  mask->header.stamp = ros::Time(kT0) + ros::Duration(t_s);
  return mask;
}

// A bag of camera_infos written here: ten at 10 Hz (the eighth with an unsupported
// distortion model), then `slow` more at 1 Hz.
class BagCameraInfoTest : public ::testing::Test {
 protected:
  void Write(int slow) {
    ros::Time::init();
    char pattern[] = "/tmp/irm_bag_camera_info_XXXXXX.bag";
    const int fd = mkstemps(pattern, 4);
    ASSERT_GE(fd, 0);
    close(fd);
    path_ = pattern;
    rosbag::Bag bag(path_, rosbag::bagmode::Write);
    for (int k = 0; k < 10; ++k) {
      sensor_msgs::CameraInfo info = MakeInfo(0.1 * k);
      if (k == 7) info.distortion_model = "equidistant";
      bag.write(kTopic, info.header.stamp, info);
    }
    for (int k = 0; k < slow; ++k) {
      const sensor_msgs::CameraInfo info = MakeInfo(2.0 + k);
      bag.write(kTopic, info.header.stamp, info);
    }
    bag.close();
    bag_.open(path_, rosbag::bagmode::Read);
  }
  void TearDown() override {
    bag_.close();
    std::remove(path_.c_str());
  }

  // The table as map_from_bag streams it: the tolerance from the first messages, then
  // every camera_info added in bag order.
  CameraInfoTable ReadAll() const {
    CameraInfoTable table(CameraInfoTable::ToleranceFromFirstMessages(bag_, kTopic));
    rosbag::View view(bag_, rosbag::TopicQuery(kTopic));
    for (const rosbag::MessageInstance& message : view) {
      table.Add(*message.instantiate<sensor_msgs::CameraInfo>());
    }
    return table;
  }

  std::string path_;
  rosbag::Bag bag_;
};

TEST_F(BagCameraInfoTest, ExactSyncComparesRosTime) {
  Write(0);
  const CameraInfoTable table = ReadAll();
  ASSERT_EQ(table.size(), 10u);
  EXPECT_NEAR(table.approximate_tolerance_s(), 0.05, 1e-6);
  CameraIntrinsics intrinsics;
  const ros::Time stamp3 = ros::Time(kT0) + ros::Duration(0.3);
  ASSERT_EQ(table.Match(stamp3, /*exact=*/true, &intrinsics), "");
  EXPECT_EQ(intrinsics.width, 640);
  // One nanosecond off is not exact.
  const std::string off = table.Match(stamp3 + ros::Duration(0, 1), true, &intrinsics);
  EXPECT_EQ(off.rfind("no_camera_info: ", 0), 0u) << off;
}

TEST_F(BagCameraInfoTest, ApproximateSyncWithinHalfAPeriod) {
  Write(0);
  const CameraInfoTable table = ReadAll();
  CameraIntrinsics intrinsics;
  const ros::Time stamp3 = ros::Time(kT0) + ros::Duration(0.3);
  EXPECT_EQ(table.Match(stamp3 + ros::Duration(0.04), false, &intrinsics), "");
  EXPECT_EQ(table.Match(stamp3 - ros::Duration(0.04), false, &intrinsics), "");
  // Beyond the last camera_info by more than half a period.
  const std::string late = table.Match(ros::Time(kT0 + 1.5), false, &intrinsics);
  EXPECT_EQ(late.rfind("no_camera_info: ", 0), 0u) << late;
}

TEST_F(BagCameraInfoTest, UnsupportedCameraInfoIsReportedForItsFrame) {
  Write(0);
  const CameraInfoTable table = ReadAll();
  CameraIntrinsics intrinsics;
  const std::string error = table.Match(ros::Time(kT0) + ros::Duration(0.7), true, &intrinsics);
  EXPECT_EQ(error.rfind("bad_camera_info: ", 0), 0u) << error;
  EXPECT_NE(error.find("equidistant"), std::string::npos) << error;
}

TEST_F(BagCameraInfoTest, ToleranceComesFromTheFirstMessagesOnly) {
  // Ten at 10 Hz, then forty at 1 Hz: the whole topic's median period is 1 s, the first
  // ten's 0.1 s.
  Write(40);
  EXPECT_NEAR(CameraInfoTable::ToleranceFromFirstMessages(bag_, kTopic, 10), 0.05, 1e-6);
  EXPECT_NEAR(CameraInfoTable::ToleranceFromFirstMessages(bag_, kTopic, 1000), 0.5, 1e-6);
  EXPECT_DOUBLE_EQ(CameraInfoTable::ToleranceFromFirstMessages(bag_, "/none"),
                   CameraInfoTable::kDefaultTolerance_s);
}

TEST(CameraInfoTableTest, EmptyTopic) {
  CameraInfoTable table;
  CameraIntrinsics intrinsics;
  EXPECT_FALSE(table.Covers(ros::Time(1.0)));
  EXPECT_EQ(table.Match(ros::Time(1.0), true, &intrinsics),
            "no_camera_info: no camera_info in the bag");
}

TEST(CameraInfoTableTest, CoversOnceACameraInfoAtOrAfterTheStampIsThere) {
  CameraInfoTable table;
  table.Add(MakeInfo(0.0));
  EXPECT_TRUE(table.Covers(ros::Time(kT0)));
  EXPECT_FALSE(table.Covers(ros::Time(kT0) + ros::Duration(0, 1)));
  table.Add(MakeInfo(0.1));
  EXPECT_TRUE(table.Covers(ros::Time(kT0) + ros::Duration(0.05)));
}

TEST(CameraInfoTableTest, ABagLoopStartsAFreshTable) {
  CameraInfoTable table;
  for (int k = 0; k < 5; ++k) table.Add(MakeInfo(0.1 * k, 640));
  ASSERT_EQ(table.size(), 5u);
  table.Add(MakeInfo(0.0, 800));  // back to the start: a new pass
  EXPECT_EQ(table.size(), 1u);
  CameraIntrinsics intrinsics;
  ASSERT_EQ(table.Match(ros::Time(kT0), true, &intrinsics), "");
  EXPECT_EQ(intrinsics.width, 800) << "the new pass's camera_info, not the old one";
  // Out of order by less than the time-jump threshold: kept, sorted.
  table.Add(MakeInfo(0.1));
  table.Add(MakeInfo(0.095));
  EXPECT_EQ(table.size(), 3u);
  EXPECT_EQ(table.Match(ros::Time(kT0) + ros::Duration(0.095), true, &intrinsics), "");
}

TEST(CameraInfoTableTest, OldEntriesAreDropped) {
  CameraInfoTable table;
  for (int k = 0; k <= 300; ++k) table.Add(MakeInfo(0.1 * k));  // 30 s at 10 Hz
  EXPECT_LE(table.size(), 102u) << "about kRetention_s (10 s) of camera_infos are kept";
  EXPECT_GE(table.size(), 100u);
  CameraIntrinsics intrinsics;
  EXPECT_EQ(table.Match(ros::Time(kT0) + ros::Duration(29.0), true, &intrinsics), "");
}

std::vector<double> Stamps(const std::vector<PairedMask>& ready) {
  std::vector<double> stamps;
  for (const PairedMask& p : ready)
    stamps.push_back((p.mask->header.stamp - ros::Time(kT0)).toSec());
  return stamps;
}

TEST(CameraInfoPairingTest, AMaskAfterItsCameraInfoIsPairedAtOnce) {
  CameraInfoPairing pairing(CameraInfoTable(0.05), /*exact=*/true);
  std::vector<PairedMask> ready;
  pairing.AddCameraInfo(MakeInfo(0.0), &ready);
  EXPECT_TRUE(ready.empty());
  pairing.AddMask(MakeMask(0.0), &ready);
  ASSERT_EQ(ready.size(), 1u);
  EXPECT_EQ(ready[0].error, "");
  EXPECT_EQ(ready[0].camera.width, 640);
  EXPECT_EQ(pairing.waiting(), 0u);
}

TEST(CameraInfoPairingTest, AMaskBeforeItsCameraInfoWaitsForIt) {
  CameraInfoPairing pairing(CameraInfoTable(0.05), /*exact=*/true);
  std::vector<PairedMask> ready;
  pairing.AddMask(MakeMask(0.0), &ready);
  pairing.AddMask(MakeMask(0.1), &ready);
  EXPECT_TRUE(ready.empty());
  EXPECT_EQ(pairing.waiting(), 2u);
  pairing.AddCameraInfo(MakeInfo(0.0), &ready);
  ASSERT_EQ(ready.size(), 1u) << "the second mask still waits for its own camera_info";
  EXPECT_EQ(ready[0].error, "");
  pairing.AddCameraInfo(MakeInfo(0.1), &ready);
  ASSERT_EQ(ready.size(), 2u);
  EXPECT_EQ(ready[1].error, "");
  const std::vector<double> stamps = Stamps(ready);
  EXPECT_NEAR(stamps[0], 0.0, 1e-6);
  EXPECT_NEAR(stamps[1], 0.1, 1e-6);
}

TEST(CameraInfoPairingTest, ApproximateWaitsForTheNextCameraInfoAndTakesTheNearest) {
  // camera_info stamped 2 ms after the masks, written before or after them.
  CameraInfoPairing pairing(CameraInfoTable(0.05), /*exact=*/false);
  std::vector<PairedMask> ready;
  pairing.AddCameraInfo(MakeInfo(0.002, 600), &ready);
  pairing.AddMask(MakeMask(0.0), &ready);
  ASSERT_EQ(ready.size(), 1u);
  EXPECT_EQ(ready[0].error, "");
  EXPECT_EQ(ready[0].camera.width, 600);
  // A mask 8 ms after the camera_info at 0.102: nearest is the previous one until a later
  // camera_info is read, then it decides.
  pairing.AddMask(MakeMask(0.110), &ready);
  EXPECT_EQ(ready.size(), 1u);
  pairing.AddCameraInfo(MakeInfo(0.102, 700), &ready);
  EXPECT_EQ(ready.size(), 1u) << "0.102 < 0.110: a nearer one may still come";
  pairing.AddCameraInfo(MakeInfo(0.202, 800), &ready);
  ASSERT_EQ(ready.size(), 2u);
  EXPECT_EQ(ready[1].error, "");
  EXPECT_EQ(ready[1].camera.width, 700);
}

TEST(CameraInfoPairingTest, TooManyWaitingOrTheEndDecidesWithWhatIsThere) {
  CameraInfoPairing pairing(CameraInfoTable(0.05), /*exact=*/true, /*max_waiting=*/3);
  std::vector<PairedMask> ready;
  for (int k = 0; k < 5; ++k) pairing.AddMask(MakeMask(0.1 * k), &ready);
  ASSERT_EQ(ready.size(), 2u) << "at most 3 wait";
  EXPECT_EQ(ready[0].error, "no_camera_info: no camera_info in the bag");
  EXPECT_EQ(pairing.waiting(), 3u);
  pairing.Flush(&ready);
  ASSERT_EQ(ready.size(), 5u);
  EXPECT_EQ(pairing.waiting(), 0u);
  const std::vector<double> stamps = Stamps(ready);
  for (std::size_t k = 0; k < stamps.size(); ++k) EXPECT_NEAR(stamps[k], 0.1 * k, 1e-6);
}

}  // namespace
}  // namespace ipm_road_mapper
