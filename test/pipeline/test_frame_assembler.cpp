// FrameAssembler: odometry interpolated at the mask stamp, frames waiting for later
// odometry, every way a frame can fail to get a pose (with its reason), time jumps and the
// queue bound.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "common/test_scene.h"
#include "ipm_road_mapper/pipeline/frame_assembler.h"

namespace ipm_road_mapper {
namespace {

// Vehicle driving along x at 10 m/s, yawing at 0.1 rad/s.
StampedPose PoseAt(double stamp) {
  StampedPose pose;
  pose.stamp = stamp;
  pose.T_map_base.linear() = RotationFromRpy(0.0, 0.0, 0.1 * stamp);
  pose.T_map_base.translation() = Eigen::Vector3d(10.0 * stamp, 0.0, 0.0);
  return pose;
}

// Constant body twist (10 m/s forward, 0.1 rad/s yaw): SE(3) interpolation is exact on it.
StampedPose ScrewPoseAt(double stamp) {
  Vector6d xi;
  xi << 10.0, 0.0, 0.0, 0.0, 0.0, 0.1;
  return {stamp, ExpSe3(stamp * xi)};
}

// A tiny 64x48 camera (the assembler only passes it through).
CameraIntrinsics SomeCamera() { return test::Intrinsics(64, 48, 50.0, 32.0, 24.0); }

cv::Mat SomeMask() { return cv::Mat(48, 64, CV_16UC1, cv::Scalar(0)); }

OdometryOptions Odometry(double tolerance_s = 0.05, double max_gap_s = 0.5) {
  OdometryOptions options;
  options.stamp_tolerance_s = tolerance_s;
  options.max_gap_s = max_gap_s;
  options.buffer_size = 100;
  return options;
}

// The reason keys ("odometry_gap" of "odometry_gap: frame at ...").
std::vector<std::string> Keys(const std::vector<std::string>& reasons) {
  std::vector<std::string> keys;
  for (const std::string& reason : reasons) keys.push_back(reason.substr(0, reason.find(':')));
  return keys;
}

TEST(FrameAssemblerTest, InterpolatesOdometryAtTheMaskStamp) {
  FrameAssembler assembler(Odometry());
  for (int i = 0; i <= 10; ++i) assembler.AddOdometry(ScrewPoseAt(1.0 + 0.02 * i));
  const cv::Mat mask = SomeMask();
  assembler.AddFrame(1.105, mask, SomeCamera());
  std::vector<std::string> skipped;
  const std::vector<FrameInput> ready = assembler.PopReady(&skipped);
  ASSERT_EQ(ready.size(), 1u);
  EXPECT_TRUE(skipped.empty());
  EXPECT_DOUBLE_EQ(ready[0].stamp, 1.105);
  EXPECT_EQ(ready[0].camera.width, 64);
  EXPECT_EQ(ready[0].mask.data, mask.data) << "the mask must be shared, not copied";
  const Eigen::Isometry3d expected = ScrewPoseAt(1.105).T_map_base;
  EXPECT_LT((ready[0].T_map_base_odom.translation() - expected.translation()).norm(), 1e-9);
  EXPECT_LT(RotationAngleBetween(ready[0].T_map_base_odom, expected), 1e-9);
  EXPECT_EQ(assembler.counters().frames_ready, 1u);
}

TEST(FrameAssemblerTest, FrameWaitsForOdometryAtOrAfterItsStamp) {
  FrameAssembler assembler(Odometry());
  assembler.AddOdometry(PoseAt(1.00));
  assembler.AddOdometry(PoseAt(1.02));
  // 1.03 is within the tolerance of the last pose, but a later pose will bracket it.
  assembler.AddFrame(1.03, SomeMask(), SomeCamera());
  std::vector<std::string> skipped;
  EXPECT_TRUE(assembler.PopReady(&skipped).empty());
  EXPECT_EQ(assembler.pending_frames(), 1u);
  assembler.AddOdometry(PoseAt(1.04));
  const std::vector<FrameInput> ready = assembler.PopReady(&skipped);
  ASSERT_EQ(ready.size(), 1u);
  EXPECT_TRUE(skipped.empty());
  EXPECT_NEAR(ready[0].T_map_base_odom.translation().x(), 10.3, 1e-9);
}

TEST(FrameAssemblerTest, OdometryExactlyAtTheStampMakesTheFrameReady) {
  FrameAssembler assembler(Odometry());
  assembler.AddOdometry(PoseAt(1.00));
  assembler.AddFrame(1.02, SomeMask(), SomeCamera());
  assembler.AddOdometry(PoseAt(1.02));
  const std::vector<FrameInput> ready = assembler.PopReady(nullptr);
  ASSERT_EQ(ready.size(), 1u);
  EXPECT_NEAR(ready[0].T_map_base_odom.translation().x(), 10.2, 1e-9);
}

TEST(FrameAssemblerTest, FlushAppliesTheToleranceRule) {
  FrameAssembler assembler(Odometry(0.05));
  assembler.AddOdometry(PoseAt(1.00));
  assembler.AddFrame(1.04, SomeMask(), SomeCamera());  // within 0.05 s of the last pose
  assembler.AddFrame(1.20, SomeMask(), SomeCamera());  // beyond it
  std::vector<std::string> skipped;
  EXPECT_TRUE(assembler.PopReady(&skipped).empty());
  const std::vector<FrameInput> ready = assembler.Flush(&skipped);
  ASSERT_EQ(ready.size(), 1u);
  EXPECT_DOUBLE_EQ(ready[0].stamp, 1.04);
  EXPECT_NEAR(ready[0].T_map_base_odom.translation().x(), 10.0, 1e-9);  // nearest, no guess
  EXPECT_EQ(Keys(skipped), std::vector<std::string>{"after_last_odometry"});
  EXPECT_EQ(assembler.pending_frames(), 0u);
}

TEST(FrameAssemblerTest, NoOdometryIsReportedNotGuessed) {
  FrameAssembler assembler(Odometry());
  assembler.AddFrame(1.0, SomeMask(), SomeCamera());
  std::vector<std::string> skipped;
  EXPECT_TRUE(assembler.PopReady(&skipped).empty());
  EXPECT_TRUE(assembler.Flush(&skipped).empty());
  ASSERT_EQ(skipped.size(), 1u);
  EXPECT_EQ(skipped[0].rfind("no_odometry: ", 0), 0u) << skipped[0];
  EXPECT_EQ(assembler.counters().frames_skipped.at("no_odometry"), 1u);
}

TEST(FrameAssemblerTest, FrameBeforeTheFirstOdometry) {
  FrameAssembler assembler(Odometry(0.05));
  assembler.AddFrame(0.5, SomeMask(), SomeCamera());
  assembler.AddOdometry(PoseAt(1.0));
  std::vector<std::string> skipped;
  EXPECT_TRUE(assembler.PopReady(&skipped).empty());
  EXPECT_EQ(Keys(skipped), std::vector<std::string>{"before_first_odometry"});
}

TEST(FrameAssemblerTest, OdometryGapSkipsTheFrame) {
  FrameAssembler assembler(Odometry(0.05, 0.5));
  assembler.AddOdometry(PoseAt(1.0));
  assembler.AddFrame(1.5, SomeMask(), SomeCamera());
  assembler.AddOdometry(PoseAt(2.0));  // 1.0 s between the bracketing poses
  assembler.AddFrame(2.1, SomeMask(), SomeCamera());
  assembler.AddOdometry(PoseAt(2.2));
  std::vector<std::string> skipped;
  const std::vector<FrameInput> ready = assembler.PopReady(&skipped);
  ASSERT_EQ(ready.size(), 1u);
  EXPECT_DOUBLE_EQ(ready[0].stamp, 2.1);
  EXPECT_EQ(Keys(skipped), std::vector<std::string>{"odometry_gap"});
}

TEST(FrameAssemblerTest, TimeJumpClearsFramesAndPosesAndIsCounted) {
  FrameAssembler assembler(Odometry());
  for (int i = 0; i <= 5; ++i) assembler.AddOdometry(PoseAt(10.0 + 0.02 * i));
  assembler.AddFrame(10.2, SomeMask(), SomeCamera());  // waits for odometry
  // The bag loops: odometry restarts at 1 s.
  EXPECT_TRUE(assembler.AddOdometry(PoseAt(1.0)));
  EXPECT_EQ(assembler.counters().time_jumps, 1u);
  std::vector<std::string> skipped;
  EXPECT_TRUE(assembler.PopReady(&skipped).empty());
  EXPECT_EQ(Keys(skipped), std::vector<std::string>{"time_jump"});
  // Frames of the new stream, older than the last frame, are not a second jump; their pose
  // comes from the new stream's odometry only.
  assembler.AddFrame(1.01, SomeMask(), SomeCamera());
  EXPECT_EQ(assembler.counters().time_jumps, 1u);
  assembler.AddOdometry(PoseAt(1.02));
  const std::vector<FrameInput> ready = assembler.PopReady(&skipped);
  ASSERT_EQ(ready.size(), 1u);
  EXPECT_NEAR(ready[0].T_map_base_odom.translation().x(), 10.1, 1e-9);
}

TEST(FrameAssemblerTest, MaskTimeJumpAlsoClears) {
  FrameAssembler assembler(Odometry());
  assembler.AddOdometry(PoseAt(5.0));
  assembler.AddFrame(5.01, SomeMask(), SomeCamera());
  assembler.AddFrame(0.5, SomeMask(), SomeCamera());  // jump: queued as the new stream
  EXPECT_EQ(assembler.counters().time_jumps, 1u);
  EXPECT_EQ(assembler.pending_frames(), 1u);
  std::vector<std::string> skipped;
  assembler.AddOdometry(PoseAt(0.48));  // older odometry: the stream was reset, no jump
  assembler.AddOdometry(PoseAt(0.52));
  EXPECT_EQ(assembler.counters().time_jumps, 1u);
  const std::vector<FrameInput> ready = assembler.PopReady(&skipped);
  ASSERT_EQ(ready.size(), 1u);
  EXPECT_DOUBLE_EQ(ready[0].stamp, 0.5);
  EXPECT_EQ(Keys(skipped), std::vector<std::string>{"time_jump"});
}

TEST(FrameAssemblerTest, SmallReorderingIsNotATimeJump) {
  FrameAssembler assembler(Odometry());
  assembler.AddOdometry(PoseAt(1.000));
  EXPECT_FALSE(assembler.AddOdometry(PoseAt(0.995)));  // within the 0.01 s epsilon
  EXPECT_FALSE(assembler.AddOdometry(PoseAt(1.000)));  // duplicate
  EXPECT_EQ(assembler.counters().odometry_out_of_order, 2u);
  assembler.AddFrame(1.0, SomeMask(), SomeCamera());
  assembler.AddFrame(1.0, SomeMask(), SomeCamera());
  EXPECT_EQ(assembler.counters().time_jumps, 0u);
  std::vector<std::string> skipped;
  EXPECT_EQ(assembler.PopReady(&skipped).size(), 1u);
  EXPECT_EQ(Keys(skipped), std::vector<std::string>{"out_of_order_frame"});
}

TEST(FrameAssemblerTest, SwappedOdometryIsReorderedNotAJump) {
  FrameAssembler assembler(Odometry());
  for (int i = 0; i <= 10; ++i) assembler.AddOdometry(PoseAt(10.0 + 0.02 * i));  // 50 Hz
  assembler.AddFrame(10.25, SomeMask(), SomeCamera());  // waits for odometry
  // 10.26 overtakes 10.24 (20 ms, one period): the late one is inserted in stamp order.
  EXPECT_TRUE(assembler.AddOdometry(PoseAt(10.26)));
  EXPECT_TRUE(assembler.AddOdometry(PoseAt(10.24)));
  EXPECT_EQ(assembler.counters().time_jumps, 0u);
  EXPECT_EQ(assembler.counters().odometry_reordered, 1u);
  EXPECT_EQ(assembler.counters().odometry_out_of_order, 0u);
  EXPECT_EQ(assembler.counters().odometry_used, 13u);
  std::vector<std::string> skipped;
  EXPECT_EQ(assembler.PopReady(&skipped).size(), 1u);  // the waiting frame was not flushed
  EXPECT_TRUE(skipped.empty());
  // A duplicate of a buffered stamp is out of order, not inserted.
  EXPECT_FALSE(assembler.AddOdometry(PoseAt(10.24)));
  EXPECT_EQ(assembler.counters().odometry_out_of_order, 1u);
  EXPECT_EQ(assembler.counters().time_jumps, 0u);
}

TEST(FrameAssemblerTest, ReorderedOdometryIsInterpolated) {
  FrameAssembler assembler(Odometry());
  for (int i = 0; i <= 10; ++i) assembler.AddOdometry(PoseAt(10.0 + 0.02 * i));
  assembler.AddOdometry(PoseAt(10.26));
  StampedPose late = PoseAt(10.24);  // marked 1 m to the left
  late.T_map_base.translation().y() = 1.0;
  ASSERT_TRUE(assembler.AddOdometry(late));
  assembler.AddFrame(10.25, SomeMask(), SomeCamera());
  std::vector<std::string> skipped;
  const std::vector<FrameInput> ready = assembler.PopReady(&skipped);
  ASSERT_EQ(ready.size(), 1u);
  // Halfway between the late pose (y = 1) and 10.26 (y = 0).
  EXPECT_NEAR(ready[0].T_map_base_odom.translation().y(), 0.5, 0.02);
}

TEST(FrameAssemblerTest, JumpBackBeyondTheReorderWindowFlushes) {
  FrameAssembler assembler(Odometry());
  for (int i = 0; i <= 10; ++i) assembler.AddOdometry(PoseAt(10.0 + 0.02 * i));
  assembler.AddFrame(10.25, SomeMask(), SomeCamera());
  // 0.08 s back is 4 periods: beyond the 3-period window, a jump.
  FrameAssembler four_periods(Odometry());
  for (int i = 0; i <= 10; ++i) four_periods.AddOdometry(PoseAt(10.0 + 0.02 * i));
  four_periods.AddOdometry(PoseAt(10.12 - 0.0001));
  EXPECT_EQ(four_periods.counters().time_jumps, 1u);
  // 2 s back: a jump; the waiting frame and the buffer are flushed.
  EXPECT_TRUE(assembler.AddOdometry(PoseAt(8.2)));
  EXPECT_EQ(assembler.counters().time_jumps, 1u);
  EXPECT_EQ(assembler.counters().odometry_reordered, 0u);
  std::vector<std::string> skipped;
  EXPECT_TRUE(assembler.PopReady(&skipped).empty());
  EXPECT_EQ(Keys(skipped), std::vector<std::string>{"time_jump"});
  EXPECT_EQ(assembler.pending_frames(), 0u);
}

TEST(FrameAssemblerTest, InvalidOdometryIsCountedAndIgnored) {
  FrameAssembler assembler(Odometry());
  StampedPose nan_pose = PoseAt(1.0);
  nan_pose.T_map_base.translation().x() = std::numeric_limits<double>::quiet_NaN();
  StampedPose not_rotation = PoseAt(1.1);
  not_rotation.T_map_base.linear() *= 2.0;
  StampedPose nan_stamp = PoseAt(1.2);
  nan_stamp.stamp = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(assembler.AddOdometry(nan_pose));
  EXPECT_FALSE(assembler.AddOdometry(not_rotation));
  EXPECT_FALSE(assembler.AddOdometry(nan_stamp));
  EXPECT_EQ(assembler.counters().bad_odometry, 3u);
  EXPECT_EQ(assembler.counters().odometry_used, 0u);
  assembler.AddFrame(1.0, SomeMask(), SomeCamera());
  std::vector<std::string> skipped;
  assembler.Flush(&skipped);
  EXPECT_EQ(Keys(skipped), std::vector<std::string>{"no_odometry"});
}

TEST(FrameAssemblerTest, NonFiniteFrameStampIsSkipped) {
  FrameAssembler assembler(Odometry());
  assembler.AddFrame(std::numeric_limits<double>::infinity(), SomeMask(), SomeCamera());
  std::vector<std::string> skipped;
  assembler.PopReady(&skipped);
  EXPECT_EQ(Keys(skipped), std::vector<std::string>{"invalid_stamp"});
}

TEST(FrameAssemblerTest, QueueIsBoundedAndDropsTheOldest) {
  FrameAssemblerOptions options;
  options.max_pending_frames = 3;
  FrameAssembler assembler(Odometry(), options);
  assembler.AddOdometry(PoseAt(1.0));
  for (int i = 1; i <= 5; ++i) assembler.AddFrame(1.0 + 0.1 * i, SomeMask(), SomeCamera());
  EXPECT_EQ(assembler.pending_frames(), 3u);
  std::vector<std::string> skipped;
  EXPECT_TRUE(assembler.PopReady(&skipped).empty());
  EXPECT_EQ(Keys(skipped), (std::vector<std::string>{"queue_overflow", "queue_overflow"}));
  EXPECT_NE(skipped[0].find("1.100 s"), std::string::npos) << skipped[0];  // the oldest
  for (int i = 1; i <= 30; ++i) assembler.AddOdometry(PoseAt(1.0 + 0.02 * i));
  const std::vector<FrameInput> ready = assembler.PopReady(&skipped);
  ASSERT_EQ(ready.size(), 3u);
  EXPECT_DOUBLE_EQ(ready[0].stamp, 1.3);
  EXPECT_DOUBLE_EQ(ready[2].stamp, 1.5);
}

TEST(FrameAssemblerTest, OverflowWithoutAnyOdometrySaysNoOdometry) {
  FrameAssemblerOptions options;
  options.max_pending_frames = 2;
  FrameAssembler assembler(Odometry(), options);
  for (int i = 1; i <= 3; ++i) assembler.AddFrame(0.1 * i, SomeMask(), SomeCamera());
  std::vector<std::string> skipped;
  assembler.PopReady(&skipped);
  EXPECT_EQ(Keys(skipped), std::vector<std::string>{"no_odometry"});
}

TEST(FrameAssemblerTest, EveryFrameIsAccountedFor) {
  FrameAssemblerOptions options;
  options.max_pending_frames = 4;
  FrameAssembler assembler(Odometry(0.05, 0.3), options);
  std::size_t ready = 0, skipped_count = 0;
  std::vector<std::string> skipped;
  for (int i = 0; i < 200; ++i) {
    const double t = 0.05 * i;
    if (i % 37 < 30) assembler.AddOdometry(PoseAt(t));  // gaps in the odometry
    if (i % 2 == 0) assembler.AddFrame(t + 0.01, SomeMask(), SomeCamera());
    ready += assembler.PopReady(&skipped).size();
  }
  ready += assembler.Flush(&skipped).size();
  skipped_count = skipped.size();
  EXPECT_EQ(ready + skipped_count, 100u);
  EXPECT_EQ(assembler.counters().frames_ready, ready);
  EXPECT_GT(skipped_count, 0u);
}

}  // namespace
}  // namespace ipm_road_mapper
