// The ROS bridge: round trips of camera_info, transforms, poses, odometry and masks, and a
// one-line error (never an exception) for every kind of bad message.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "ipm_road_mapper/ros/msg_conversion.h"

namespace ipm_road_mapper {
namespace {

CameraIntrinsics SomeIntrinsics() {
  CameraIntrinsics in;
  in.width = 1280;
  in.height = 720;
  in.fx = 1000.0;
  in.fy = 1001.0;
  in.cx = 640.5;
  in.cy = 360.25;
  in.distortion = {-0.1, 0.01, 0.001, -0.002, 0.0005};
  return in;
}

Eigen::Isometry3d SomePose() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = RotationFromRpy(0.1, -0.2, 2.5);
  T.translation() = Eigen::Vector3d(1.5, -0.25, 1.75);
  return T;
}

bool StartsWith(const std::string& text, const std::string& prefix) {
  return text.rfind(prefix, 0) == 0;
}

TEST(MsgConversionTest, CameraInfoRoundTrip) {
  const CameraIntrinsics in = SomeIntrinsics();
  const sensor_msgs::CameraInfo msg = IntrinsicsToCameraInfo(in);
  EXPECT_EQ(msg.distortion_model, "plumb_bob");
  CameraIntrinsics out;
  ASSERT_EQ(CameraInfoToIntrinsics(msg, &out), "");
  EXPECT_EQ(out.width, 1280);
  EXPECT_EQ(out.height, 720);
  EXPECT_DOUBLE_EQ(out.fx, in.fx);
  EXPECT_DOUBLE_EQ(out.fy, in.fy);
  EXPECT_DOUBLE_EQ(out.cx, in.cx);
  EXPECT_DOUBLE_EQ(out.cy, in.cy);
  EXPECT_EQ(out.distortion, in.distortion);
}

TEST(MsgConversionTest, CameraInfoWithoutDistortion) {
  sensor_msgs::CameraInfo msg = IntrinsicsToCameraInfo(SomeIntrinsics());
  msg.D.clear();
  CameraIntrinsics out;
  ASSERT_EQ(CameraInfoToIntrinsics(msg, &out), "");  // plumb_bob with an empty D
  EXPECT_EQ(out.distortion, (std::array<double, 5>{0, 0, 0, 0, 0}));
  msg.distortion_model = "";
  EXPECT_EQ(CameraInfoToIntrinsics(msg, &out), "");  // no model, no D
  msg.D = {0, 0, 0, 0, 0};
  EXPECT_EQ(CameraInfoToIntrinsics(msg, &out), "");  // no model, zero D
}

TEST(MsgConversionTest, CameraInfoBadDistortionModel) {
  sensor_msgs::CameraInfo msg = IntrinsicsToCameraInfo(SomeIntrinsics());
  msg.distortion_model = "rational_polynomial";
  msg.D = {0.1, 0.01, 0, 0, 0, 0.1, 0.01, 0};
  CameraIntrinsics out;
  out.fx = 42.0;
  const std::string error = CameraInfoToIntrinsics(msg, &out);
  EXPECT_NE(error.find("unsupported distortion model 'rational_polynomial'"), std::string::npos)
      << error;
  EXPECT_DOUBLE_EQ(out.fx, 42.0) << "untouched on error";

  msg.distortion_model = "";
  msg.D = {0.1, 0, 0, 0, 0};  // a D without a model: ambiguous
  EXPECT_NE(CameraInfoToIntrinsics(msg, &out), "");
  msg.distortion_model = "plumb_bob";
  msg.D = {0.1, 0.01, 0.0, 0.0};
  EXPECT_NE(CameraInfoToIntrinsics(msg, &out).find("5 distortion coefficients, got 4"),
            std::string::npos);
}

TEST(MsgConversionTest, CameraInfoOtherBadFields) {
  const sensor_msgs::CameraInfo good = IntrinsicsToCameraInfo(SomeIntrinsics());
  CameraIntrinsics out;
  sensor_msgs::CameraInfo msg = good;
  msg.K[0] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(CameraInfoToIntrinsics(msg, &out).find("not finite"), std::string::npos);
  msg = good;
  msg.binning_x = 2;
  EXPECT_NE(CameraInfoToIntrinsics(msg, &out).find("binning"), std::string::npos);
  msg = good;
  msg.roi.x_offset = 10;
  msg.roi.width = 100;
  EXPECT_NE(CameraInfoToIntrinsics(msg, &out).find("region of interest"), std::string::npos);
  msg = good;
  msg.roi.width = 1280;  // a full-image ROI is fine
  msg.roi.height = 720;
  EXPECT_EQ(CameraInfoToIntrinsics(msg, &out), "");
}

TEST(MsgConversionTest, TransformRoundTrip) {
  const Eigen::Isometry3d T = SomePose();
  Eigen::Isometry3d back;
  ASSERT_EQ(TransformToIsometry(IsometryToTransform(T), &back), "");
  EXPECT_TRUE(back.isApprox(T, 1e-12));

  const geometry_msgs::TransformStamped stamped =
      IsometryToTransformStamped(T, ros::Time(12, 500), "base_link", "camera_optical");
  EXPECT_EQ(stamped.header.frame_id, "base_link");
  EXPECT_EQ(stamped.child_frame_id, "camera_optical");
  EXPECT_EQ(stamped.header.stamp, ros::Time(12, 500));
  ASSERT_EQ(TransformToIsometry(stamped.transform, &back), "");
  EXPECT_TRUE(back.isApprox(T, 1e-12));
  // T maps child points into the parent: the child's origin lands at the translation.
  EXPECT_DOUBLE_EQ(stamped.transform.translation.x, 1.5);
}

TEST(MsgConversionTest, PoseRoundTrip) {
  const Eigen::Isometry3d T = SomePose();
  Eigen::Isometry3d back;
  ASSERT_EQ(PoseToIsometry(IsometryToPose(T), &back), "");
  EXPECT_TRUE(back.isApprox(T, 1e-12));
}

TEST(MsgConversionTest, BadQuaternions) {
  geometry_msgs::Transform msg = IsometryToTransform(SomePose());
  Eigen::Isometry3d T;
  msg.rotation.x = msg.rotation.y = msg.rotation.z = msg.rotation.w = 0.0;
  EXPECT_TRUE(StartsWith(TransformToIsometry(msg, &T), "transform: quaternion is not unit"));
  msg.rotation.w = std::numeric_limits<double>::infinity();
  EXPECT_TRUE(StartsWith(TransformToIsometry(msg, &T), "transform: quaternion is not finite"));
  msg.rotation.w = 1.0005;  // slightly off: normalized
  ASSERT_EQ(TransformToIsometry(msg, &T), "");
  EXPECT_TRUE(IsValidTransform(T));
  msg.translation.y = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(TransformToIsometry(msg, &T), "");
}

TEST(MsgConversionTest, Odometry) {
  nav_msgs::Odometry msg;
  msg.header.stamp = ros::Time(100, 250000000);
  msg.header.frame_id = "odom";
  msg.child_frame_id = "base_link";
  msg.pose.pose = IsometryToPose(SomePose());
  StampedPose pose;
  ASSERT_EQ(OdometryToStampedPose(msg, &pose), "");
  EXPECT_DOUBLE_EQ(pose.stamp, 100.25);
  EXPECT_TRUE(pose.T_map_base.isApprox(SomePose(), 1e-12));

  msg.pose.pose.orientation.w = 5.0;
  pose.stamp = -1.0;
  EXPECT_TRUE(StartsWith(OdometryToStampedPose(msg, &pose), "odometry: pose: quaternion"));
  EXPECT_DOUBLE_EQ(pose.stamp, -1.0) << "untouched on error";
}

cv::Mat SomeMask() {
  cv::Mat mask(72, 128, CV_16UC1, cv::Scalar(0));
  mask(cv::Rect(10, 20, 30, 15)).setTo(10001);
  mask(cv::Rect(60, 5, 8, 60)).setTo(2001);
  mask.at<std::uint16_t>(71, 127) = 65535;
  return mask;
}

TEST(MsgConversionTest, MaskRoundTrip) {
  const cv::Mat mask = SomeMask();
  const sensor_msgs::Image msg = MaskToImage(mask);
  EXPECT_EQ(msg.encoding, "16UC1");
  EXPECT_EQ(msg.width, 128u);
  cv::Mat back;
  ASSERT_EQ(ImageToMask(msg, &back), "");
  ASSERT_EQ(back.type(), CV_16UC1);
  EXPECT_EQ(cv::countNonZero(back != mask), 0);
  EXPECT_NE(static_cast<const void*>(back.data), static_cast<const void*>(msg.data.data()))
      << "the mask owns its pixels";
}

TEST(MsgConversionTest, MaskMono16PaddedRowsAndForeignByteOrder) {
  const cv::Mat mask = SomeMask();
  sensor_msgs::Image msg = MaskToImage(mask);
  msg.encoding = "mono16";
  // Re-pack with 6 padding bytes per row and the other byte order.
  sensor_msgs::Image padded = msg;
  padded.is_bigendian = !msg.is_bigendian;
  padded.step = msg.step + 6;
  padded.data.assign(static_cast<std::size_t>(padded.step) * msg.height, 0xAB);
  for (std::uint32_t row = 0; row < msg.height; ++row) {
    for (std::uint32_t byte = 0; byte < msg.step; byte += 2) {
      padded.data[row * padded.step + byte] = msg.data[row * msg.step + byte + 1];
      padded.data[row * padded.step + byte + 1] = msg.data[row * msg.step + byte];
    }
  }
  cv::Mat back;
  ASSERT_EQ(ImageToMask(padded, &back), "");
  EXPECT_EQ(cv::countNonZero(back != mask), 0);
}

TEST(MsgConversionTest, MaskBadEncodingAndSizes) {
  sensor_msgs::Image msg = MaskToImage(SomeMask());
  cv::Mat back;
  msg.encoding = "rgb8";
  EXPECT_EQ(ImageToMask(msg, &back), "mask encoding is 'rgb8', expected 16UC1 or mono16");
  EXPECT_TRUE(back.empty()) << "untouched on error";
  msg.encoding = "8UC1";
  EXPECT_NE(ImageToMask(msg, &back).find("'8UC1'"), std::string::npos);
  msg.encoding = "16UC1";
  msg.step = 100;  // < width * 2
  EXPECT_NE(ImageToMask(msg, &back).find("step"), std::string::npos);
  msg.step = 256;
  msg.data.resize(1000);  // truncated
  EXPECT_NE(ImageToMask(msg, &back).find("bytes"), std::string::npos);
  msg.width = 0;
  EXPECT_EQ(ImageToMask(msg, &back), "mask image is empty");
  EXPECT_TRUE(back.empty());
  EXPECT_EQ(MaskToImage(cv::Mat(4, 4, CV_8UC1)).width, 0u);
}

}  // namespace
}  // namespace ipm_road_mapper
