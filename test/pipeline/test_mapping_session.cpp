// The frame pipeline shared by map_from_bag and the nodelet: frames before the extrinsic
// are counted and handed to the Mapper when it starts; frames get interpolated poses;
// missing odometry is decided after odometry_wait_s (live) or left waiting (offline);
// lagging but present odometry never triggers it; reset keeps mapping.
#include <gtest/gtest.h>

#include <chrono>

#include "common/test_scene.h"
#include "ipm_road_mapper/pipeline/mapping_session.h"

namespace ipm_road_mapper {
namespace {

// A 640x480 camera.
CameraIntrinsics Camera() { return test::Intrinsics(640, 480, 500.0, 320.0, 240.0); }

Eigen::Isometry3d Extrinsic() { return test::MountedCamera(0.0, 5.0 * M_PI / 180.0, 0.0); }

MapperOptions Options() {
  MapperOptions o;
  o.backend.enabled = false;
  return o;
}

ClassTable Classes() {
  return ClassTable::Load(OptionsReader(YAML::Load(R"(
classes:
  - {id: 10, name: arrow_straight, kind: marking}
)"),
                                        ""));
}

cv::Mat EmptyMask() { return cv::Mat(480, 640, CV_16UC1, cv::Scalar(0)); }

StampedPose Pose(double stamp) {
  StampedPose p;
  p.stamp = stamp;
  p.T_map_base.translation() = Eigen::Vector3d(10.0 * stamp, 0.0, 0.0);
  return p;
}

std::size_t CountPrefix(const std::vector<std::string>& reasons, const std::string& prefix) {
  std::size_t n = 0;
  for (const std::string& r : reasons) n += r.rfind(prefix, 0) == 0;
  return n;
}

TEST(MappingSession, FramesBeforeTheExtrinsicAreCountedAndHandedOver) {
  MappingSession session(Options(), Classes());
  SessionUpdate update;
  session.AddFrame(1.0, EmptyMask(), Camera(), &update);
  session.CountSkipped("bad_mask_encoding: rgb8", &update);
  EXPECT_FALSE(session.started());
  EXPECT_EQ(session.mapper(), nullptr);
  EXPECT_EQ(session.skipped_before_start().at("no_extrinsic"), 1u);
  EXPECT_EQ(session.skipped_before_start().at("bad_mask_encoding"), 1u);
  EXPECT_EQ(update.skipped.size(), 2u);
  session.Start(Extrinsic());
  ASSERT_NE(session.mapper(), nullptr);
  EXPECT_EQ(session.mapper()->counters().frames_skipped.at("no_extrinsic"), 1u);
  EXPECT_EQ(session.mapper()->counters().frames_skipped.at("bad_mask_encoding"), 1u);
  session.Start(Eigen::Isometry3d::Identity());  // idempotent
  EXPECT_TRUE(session.mapper()->T_base_cam_initial().isApprox(Extrinsic()));
}

TEST(MappingSession, FramesGetInterpolatedPoses) {
  MappingSession session(Options(), Classes());
  session.Start(Extrinsic());
  SessionUpdate update;
  session.AddOdometry(Pose(0.0), &update);
  session.AddFrame(0.05, EmptyMask(), Camera(), &update);
  EXPECT_TRUE(update.used.empty());  // waits for odometry after its stamp
  session.AddOdometry(Pose(0.1), &update);
  ASSERT_EQ(update.used.size(), 1u);
  EXPECT_NEAR(update.used[0].T_map_base_odom.translation().x(), 0.5, 1e-9);
  EXPECT_EQ(session.mapper()->counters().frames_used, 1u);
  ASSERT_EQ(session.mapper()->map().frames.size(), 1u);
}

TEST(MappingSession, MissingOdometryIsDecidedAfterTheWait) {
  MappingSession session(Options(), Classes(), 1.0);
  session.Start(Extrinsic());
  SessionUpdate update;
  for (int i = 0; i <= 5; ++i) session.AddOdometry(Pose(0.1 * i), &update);  // until 0.5 s
  for (int i = 6; i <= 20; ++i) session.AddFrame(0.1 * i, EmptyMask(), Camera(), &update);
  // Frames 0.6.. waited; when the newest mask (1.7 s) was 1 s past both the newest odometry
  // (0.5 s) and the oldest waiting mask (0.6 s), the waiting ones were decided: skipped.
  EXPECT_TRUE(update.used.empty());
  EXPECT_GE(CountPrefix(update.skipped, "after_last_odometry"), 11u);
  EXPECT_LT(session.assembler().pending_frames(), 5u);
}

TEST(MappingSession, OfflineKeepsFramesWaiting) {
  MappingSession session(Options(), Classes(), 0.0);
  session.Start(Extrinsic());
  SessionUpdate update;
  session.AddOdometry(Pose(0.0), &update);
  for (int i = 1; i <= 20; ++i) session.AddFrame(0.1 * i, EmptyMask(), Camera(), &update);
  EXPECT_TRUE(update.skipped.empty());
  EXPECT_EQ(session.assembler().pending_frames(), 20u);
  session.Finish(&update);  // end of input: decided by the tolerance rule
  EXPECT_EQ(session.assembler().pending_frames(), 0u);
  EXPECT_EQ(update.skipped.size(), 20u);
}

TEST(MappingSession, LaggingOdometryIsNotMissingOdometry) {
  MappingSession session(Options(), Classes(), 1.0);
  session.Start(Extrinsic());
  SessionUpdate update;
  // Odometry arrives 0.3 s behind the masks, for 5 s.
  for (int i = 0; i < 100; ++i) {
    session.AddFrame(0.05 * i + 0.3, EmptyMask(), Camera(), &update);
    session.AddOdometry(Pose(0.05 * i), &update);
  }
  EXPECT_TRUE(update.skipped.empty()) << update.skipped.front();
  EXPECT_GE(update.used.size(), 90u);
}

TEST(MappingSession, ResetKeepsMapping) {
  MappingSession session(Options(), Classes());
  session.Start(Extrinsic());
  SessionUpdate update;
  session.AddOdometry(Pose(0.0), &update);
  session.AddFrame(0.05, EmptyMask(), Camera(), &update);
  session.AddOdometry(Pose(0.1), &update);
  ASSERT_EQ(update.used.size(), 1u);
  session.Reset();
  EXPECT_TRUE(session.mapper()->map().frames.empty());
  // A new stream, older stamps (a restarted player): mapped again after the reset.
  update = SessionUpdate();
  session.AddOdometry(Pose(0.0), &update);
  session.AddFrame(0.02, EmptyMask(), Camera(), &update);
  session.AddOdometry(Pose(0.1), &update);
  EXPECT_EQ(update.used.size(), 1u);
}

TEST(MappingSession, FinishWithATimeBudgetDecidesTheWaitingFramesAndSolves) {
  MapperOptions options = Options();
  options.backend.enabled = true;  // the optimizer thread, as in the nodelet
  MappingSession session(options, Classes());
  session.Finish(nullptr, 1.0);  // before Start: nothing to do, no crash
  session.Start(Extrinsic());
  SessionUpdate update;
  session.AddOdometry(Pose(0.0), &update);
  for (int i = 1; i <= 5; ++i) session.AddFrame(0.02 * i, EmptyMask(), Camera(), &update);
  EXPECT_EQ(session.assembler().pending_frames(), 5u);
  const auto start = std::chrono::steady_clock::now();
  session.Finish(&update, 2.0);
  const double elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(session.assembler().pending_frames(), 0u);
  EXPECT_EQ(update.used.size() + update.skipped.size(), 5u);
  EXPECT_LT(elapsed_s, 2.0 + 1.0);  // five empty frames: far inside the budget
}

}  // namespace
}  // namespace ipm_road_mapper
