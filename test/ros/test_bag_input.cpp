// Bag input helpers: topic checks and the extrinsic from a chain of /tf_static transforms, on
// a small bag written here (camera_info <-> mask pairing: test_bag_camera_info.cpp).
#include <gtest/gtest.h>
#include <rosbag/bag.h>
#include <stdlib.h>
#include <tf2_msgs/TFMessage.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "common/test_scene.h"
#include "ipm_road_mapper/ros/bag_input.h"
#include "ipm_road_mapper/ros/msg_conversion.h"

namespace ipm_road_mapper {
namespace {

constexpr double kT0 = 1700000000.0;  // epoch stamps: doubles are too coarse for "exact"

Eigen::Isometry3d MakePose(double x, double y, double z, double roll, double pitch, double yaw) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = RotationFromRpy(roll, pitch, yaw);
  T.translation() = Eigen::Vector3d(x, y, z);
  return T;
}

class BagInputTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ros::Time::init();
    char pattern[] = "/tmp/irm_bag_input_XXXXXX.bag";
    const int fd = mkstemps(pattern, 4);
    ASSERT_GE(fd, 0);
    close(fd);
    path_ = pattern;
    rosbag::Bag bag(path_, rosbag::bagmode::Write);
    // base_link -> camera_link -> camera_optical, in two messages.
    tf2_msgs::TFMessage first, second;
    first.transforms.push_back(
        IsometryToTransformStamped(T_base_link_, ros::Time(kT0), "base_link", "camera_link"));
    second.transforms.push_back(IsometryToTransformStamped(T_link_optical_, ros::Time(kT0),
                                                           "camera_link", "camera_optical"));
    bag.write("/tf_static", ros::Time(kT0), first);
    bag.write("/tf_static", ros::Time(kT0), second);
    const CameraIntrinsics intrinsics = test::Intrinsics(640, 480, 500.0, 320.0, 240.0);
    for (int k = 0; k < 10; ++k) {
      sensor_msgs::CameraInfo info = IntrinsicsToCameraInfo(intrinsics);
      info.header.stamp = ros::Time(kT0) + ros::Duration(0.1 * k);
      if (k == 7) info.distortion_model = "equidistant";
      bag.write("/camera/camera_info", info.header.stamp, info);
    }
    bag.close();
    bag_.open(path_, rosbag::bagmode::Read);
  }
  void TearDown() override {
    bag_.close();
    std::remove(path_.c_str());
  }

  const Eigen::Isometry3d T_base_link_ = MakePose(1.2, 0.1, 1.4, 0.0, 0.05, 0.0);
  const Eigen::Isometry3d T_link_optical_ = MakePose(0.0, 0.0, 0.0, -M_PI / 2, 0.0, -M_PI / 2);
  std::string path_;
  rosbag::Bag bag_;
};

TEST_F(BagInputTest, TopicChecks) {
  const auto types = BagTopicTypes(bag_);
  EXPECT_EQ(types.at("/camera/camera_info"), "sensor_msgs/CameraInfo");
  EXPECT_EQ(CheckBagTopics(bag_, {{"/camera/camera_info", "sensor_msgs/CameraInfo"}}), "");
  const std::string missing = CheckBagTopics(bag_, {{"/odom", "nav_msgs/Odometry"}});
  EXPECT_NE(missing.find("topic /odom (nav_msgs/Odometry) is not in the bag"), std::string::npos)
      << missing;
  EXPECT_NE(missing.find("/tf_static"), std::string::npos) << "lists the bag's topics";
  const std::string wrong = CheckBagTopics(bag_, {{"/camera/camera_info", "sensor_msgs/Image"}});
  EXPECT_NE(wrong.find("has type sensor_msgs/CameraInfo"), std::string::npos) << wrong;
}

TEST_F(BagInputTest, StaticTransformChainIsComposed) {
  Eigen::Isometry3d T_base_cam;
  ASSERT_EQ(LookupStaticTransform(bag_, "base_link", "camera_optical", &T_base_cam), "");
  EXPECT_TRUE(T_base_cam.isApprox(T_base_link_ * T_link_optical_, 1e-9));
  // The direction matters: the inverse lookup gives the inverse transform.
  Eigen::Isometry3d T_cam_base;
  ASSERT_EQ(LookupStaticTransform(bag_, "camera_optical", "base_link", &T_cam_base), "");
  EXPECT_TRUE(T_cam_base.isApprox(T_base_cam.inverse(), 1e-9));
}

TEST_F(BagInputTest, MissingStaticTransform) {
  Eigen::Isometry3d T;
  const std::string error = LookupStaticTransform(bag_, "base_link", "lidar", &T);
  EXPECT_NE(error.find("no transform base_link -> lidar"), std::string::npos) << error;
}

// Writes the first `bytes` bytes of `from` to `to` (all when bytes is npos), with the 8 bytes
// after "index_pos=" in the file header zeroed when `unclose`.
void CopyBag(const std::string& from, const std::string& to, std::size_t bytes, bool unclose) {
  std::ifstream in(from, std::ios::binary);
  std::string data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (bytes != std::string::npos) data.resize(bytes);
  if (unclose) {
    const std::size_t at = data.find("index_pos=");
    ASSERT_LT(at, 4096u);
    data.replace(at + 10, 8, std::string(8, '\0'));
  }
  std::ofstream(to, std::ios::binary) << data;
}

TEST_F(BagInputTest, IndexCheckOfAnIntactBag) {
  const BagIndexCheck check = CheckBagIndex(path_);
  EXPECT_TRUE(check.is_bag_v2);
  EXPECT_FALSE(check.index_missing);
  EXPECT_EQ(check.problem, "");
  rosbag::Bag bag;
  EXPECT_EQ(OpenBagForReading(path_, &bag), "");
  EXPECT_TRUE(bag.isOpen());
}

TEST_F(BagInputTest, IndexCheckOfATruncatedBag) {
  const std::string cut = path_ + ".cut.bag";
  const std::size_t size = std::filesystem::file_size(path_);
  // Half: before the index (this bag is small, its index a large part of it; a cut inside the
  // index is not detected from the header, map_from_bag then suggests reindexing too).
  CopyBag(path_, cut, size / 2, false);
  rosbag::Bag bag;
  EXPECT_THROW(bag.open(cut, rosbag::bagmode::Read), rosbag::BagException)
      << "rosbag's C++ API refuses a bag without its index (what map_from_bag must explain)";
  const BagIndexCheck check = CheckBagIndex(cut);
  EXPECT_TRUE(check.is_bag_v2);
  EXPECT_TRUE(check.index_missing);
  EXPECT_NE(check.problem.find("truncated"), std::string::npos) << check.problem;
  const std::string error = OpenBagForReading(cut, &bag);
  EXPECT_NE(error.find("truncated"), std::string::npos) << error;
  EXPECT_NE(error.find("run `rosbag reindex " + cut + "`"), std::string::npos) << error;
  EXPECT_EQ(error.find('\n'), std::string::npos) << "one line";
  // Cut inside the index: not visible in the header, still the suggestion.
  CopyBag(path_, cut, size - 10, false);
  const std::string index_error = OpenBagForReading(cut, &bag);
  EXPECT_NE(index_error.find("rosbag reindex"), std::string::npos) << index_error;
  std::remove(cut.c_str());
}

TEST_F(BagInputTest, IndexCheckOfAnUnclosedBag) {
  const std::string open = path_ + ".open.bag";
  CopyBag(path_, open, std::string::npos, true);
  const BagIndexCheck check = CheckBagIndex(open);
  EXPECT_TRUE(check.is_bag_v2);
  EXPECT_TRUE(check.index_missing);
  EXPECT_NE(check.problem.find("no index"), std::string::npos) << check.problem;
  std::remove(open.c_str());
}

TEST_F(BagInputTest, IndexCheckOfNotABag) {
  const std::string garbage = path_ + ".txt";
  std::ofstream(garbage) << "not a bag at all, but longer than the version line";
  EXPECT_FALSE(CheckBagIndex(garbage).is_bag_v2);
  EXPECT_FALSE(CheckBagIndex(garbage).index_missing);
  EXPECT_FALSE(CheckBagIndex(garbage).problem.empty());
  rosbag::Bag bag;
  const std::string error = OpenBagForReading(garbage, &bag);
  EXPECT_NE(error.find("not a ROS bag"), std::string::npos) << error;
  EXPECT_EQ(error.find("reindex"), std::string::npos) << error;
  EXPECT_FALSE(CheckBagIndex(path_ + ".missing").is_bag_v2);
  std::remove(garbage.c_str());
  // A version line and then nothing: a damaged header, not a crash.
  std::ofstream(garbage) << "#ROSBAG V2.0\n\xff\xff\xff\x7f";
  EXPECT_FALSE(CheckBagIndex(garbage).is_bag_v2);
  std::remove(garbage.c_str());
}

}  // namespace
}  // namespace ipm_road_mapper
