// The diagnostics' status functions: skip reasons appear as keys with their counts (before
// and after the Mapper started), levels say when nothing is used or inputs are missing, the
// extrinsic change is reported in degrees and meters.
#include <gtest/gtest.h>

#include "ipm_road_mapper/ros/mapper_diagnostics.h"

namespace ipm_road_mapper {
namespace {

using diagnostic_msgs::DiagnosticStatus;
using diagnostic_updater::DiagnosticStatusWrapper;

std::string Value(const DiagnosticStatusWrapper& s, const std::string& key) {
  for (const auto& kv : s.values) {
    if (kv.key == key) return kv.value;
  }
  return "<missing>";
}

InputStats Flowing() {
  InputStats in;
  in.rates_hz = {20.0, 20.0, 20.0, 50.0, 0.0};
  in.totals = {100, 98, 98, 250, 0};
  return in;
}

TEST(MapperDiagnostics, SkipReasonsAndSyncDrops) {
  MapperStatusSnapshot previous, now;
  now.started = true;
  now.counters.frames_used = 90;
  now.counters.frames_skipped = {{"bad_mask", 3}, {"no_odometry", 5}};
  previous = now;
  previous.counters.frames_used = 80;
  DiagnosticStatusWrapper s;
  FillFrameStatus(now, previous, Flowing(), &s);
  EXPECT_EQ(Value(s, "frames used"), "90");
  EXPECT_EQ(Value(s, "frames skipped"), "8");
  EXPECT_EQ(Value(s, "skipped: bad_mask"), "3");
  EXPECT_EQ(Value(s, "skipped: no_odometry"), "5");
  EXPECT_EQ(Value(s, "masks dropped by the sync (no camera_info)"), "2");
  EXPECT_EQ(s.level, DiagnosticStatus::OK);

  // Frames skipped during the period and none used: WARN.
  previous = now;
  now.counters.frames_skipped["bad_mask"] = 10;
  DiagnosticStatusWrapper warn;
  FillFrameStatus(now, previous, Flowing(), &warn);
  EXPECT_EQ(warn.level, DiagnosticStatus::WARN);
}

TEST(MapperDiagnostics, AClassTableThatIsNotTheMasksOwnWarns) {
  MapperStatusSnapshot previous, now;
  now.started = true;
  now.counters.frames_used = 90;
  now.counters.extraction.dropped_oversized = 158;
  previous = now;
  previous.counters.frames_used = 80;
  DiagnosticStatusWrapper ok;
  FillFrameStatus(now, previous, Flowing(), &ok);
  EXPECT_EQ(ok.level, DiagnosticStatus::OK);
  EXPECT_EQ(Value(ok, "marking views dropped: oversized"), "158");
  EXPECT_EQ(Value(ok, "class table"), "<missing>");
  now.class_table_warnings = {"class 10 'arrow_straight' (at most 10.0 x 4.0 m): 158 of 236"};
  DiagnosticStatusWrapper warn;
  FillFrameStatus(now, previous, Flowing(), &warn);
  EXPECT_EQ(warn.level, DiagnosticStatus::WARN);
  EXPECT_NE(warn.message.find("class table"), std::string::npos) << warn.message;
  EXPECT_EQ(Value(warn, "class table"), now.class_table_warnings[0]);
}

TEST(MapperDiagnostics, QueueDropsWarnAndPublishCpuIsShown) {
  MapperStatusSnapshot previous, now;
  now.started = true;
  now.counters.frames_used = 50;
  previous = now;
  previous.counters.frames_used = 40;
  now.inputs_dropped = {2, 7, 0};
  now.publishes = 12;
  now.publish_cpu_last_ms = 0.25;
  now.publish_cpu_mean_ms = 0.2;
  now.publish_cpu_max_ms = 0.5;
  DiagnosticStatusWrapper s;
  FillFrameStatus(now, previous, Flowing(), &s);
  EXPECT_EQ(Value(s, "inputs dropped (queue full): frames"), "2");
  EXPECT_EQ(Value(s, "inputs dropped (queue full): odometry"), "7");
  EXPECT_EQ(Value(s, "inputs dropped (queue full): images"), "0");
  EXPECT_EQ(Value(s, "publishes"), "12");
  EXPECT_EQ(Value(s, "publish_cpu_ms"), "0.250");
  EXPECT_EQ(Value(s, "publish_cpu_ms mean"), "0.200");
  EXPECT_EQ(Value(s, "publish_cpu_ms max"), "0.500");
  EXPECT_EQ(s.level, DiagnosticStatus::WARN);  // drops during the period
  EXPECT_NE(s.message.find("falls behind"), std::string::npos);
  // No new drop in the next period: OK again.
  previous = now;
  now.counters.frames_used = 60;
  DiagnosticStatusWrapper ok;
  FillFrameStatus(now, previous, Flowing(), &ok);
  EXPECT_EQ(ok.level, DiagnosticStatus::OK);
}

TEST(MapperDiagnostics, BeforeStartTheSessionCountsAreShown) {
  MapperStatusSnapshot now;
  now.skipped_before_start = {{"no_extrinsic", 7}};
  DiagnosticStatusWrapper s;
  FillFrameStatus(now, MapperStatusSnapshot(), Flowing(), &s);
  EXPECT_EQ(Value(s, "skipped: no_extrinsic"), "7");
  EXPECT_EQ(Value(s, "lanes dropped: doubling back"), "0");
  now.counters.extraction.dropped_doubled_lane = 2;
  now.counters.extraction.dropped_wide_lane = 3;
  DiagnosticStatusWrapper bad_lanes;
  FillFrameStatus(now, MapperStatusSnapshot(), Flowing(), &bad_lanes);
  EXPECT_EQ(Value(bad_lanes, "lanes dropped: doubling back"), "2");
  EXPECT_EQ(Value(bad_lanes, "lanes dropped: wider than a line"), "3");
  EXPECT_EQ(s.level, DiagnosticStatus::WARN);
  DiagnosticStatusWrapper e;
  now.extrinsic_status = "no extrinsic base_link -> cam: frame does not exist";
  FillExtrinsicStatus(now, &e);
  EXPECT_EQ(e.level, DiagnosticStatus::WARN);
  EXPECT_EQ(Value(e, "source"), now.extrinsic_status);
}

TEST(MapperDiagnostics, InputLevels) {
  InputStats in = Flowing();
  DiagnosticStatusWrapper ok;
  FillInputStatus(in, &ok);
  EXPECT_EQ(ok.level, DiagnosticStatus::OK);
  EXPECT_EQ(Value(ok, "masks rate (Hz)"), "20.00");
  in.rates_hz[static_cast<int>(MapperInput::kOdometry)] = 0.0;
  DiagnosticStatusWrapper no_odom;
  FillInputStatus(in, &no_odom);
  EXPECT_EQ(no_odom.level, DiagnosticStatus::WARN);
  EXPECT_NE(no_odom.message.find("odometry"), std::string::npos);
}

TEST(MapperDiagnostics, ExtrinsicChangeAndSolveTimes) {
  MapperStatusSnapshot now;
  now.started = true;
  now.extrinsic_status = "tf base_link -> cam";
  now.T_base_cam.linear() =
      Eigen::AngleAxisd(0.5 * M_PI / 180.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
  now.T_base_cam.translation() = Eigen::Vector3d(0.03, 0.0, 0.04);
  DiagnosticStatusWrapper e;
  FillExtrinsicStatus(now, &e);
  EXPECT_EQ(Value(e, "change rotation (deg)"), "0.5000");
  EXPECT_EQ(Value(e, "change translation (m)"), "0.0500");
  EXPECT_EQ(Value(e, "observed"), "none");
  now.T_base_cam_covariance = Eigen::Matrix<double, 6, 6>::Identity() * 1e-4;  // 1 cm, 0.57 deg
  now.extrinsic_observed = {false, true, true, false, false, true};
  now.counters.extrinsic_rejected = 3;
  DiagnosticStatusWrapper calibrated;
  FillExtrinsicStatus(now, &calibrated);
  EXPECT_EQ(Value(calibrated, "sigma xyz (m)"), "0.0100 0.0100 0.0100");
  EXPECT_EQ(Value(calibrated, "sigma rpy (deg)"), "0.5730 0.5730 0.5730");
  EXPECT_EQ(Value(calibrated, "observed"), "pitch yaw z");
  EXPECT_EQ(Value(calibrated, "updates rejected (held-out frames)"), "3");
  now.backend_enabled = true;
  now.backend.solved = 2;
  now.backend.solve_times_s = {0.1, 0.3};
  DiagnosticStatusWrapper o;
  FillOptimizerStatus(now, MapperStatusSnapshot(), &o);
  EXPECT_EQ(Value(o, "solve time mean (ms)"), "200.0");
  EXPECT_EQ(Value(o, "solve time max (ms)"), "300.0");
  EXPECT_EQ(o.level, DiagnosticStatus::OK);
  MapperStatusSnapshot later = now;
  later.backend.unusable = 1;
  DiagnosticStatusWrapper w;
  FillOptimizerStatus(later, now, &w);
  EXPECT_EQ(w.level, DiagnosticStatus::WARN);
  // Windows dropped because the optimizer's queue was full: it falls behind.
  MapperStatusSnapshot behind = later;
  behind.backend.dropped_queue_full = now.backend.dropped_queue_full + 3;
  DiagnosticStatusWrapper b;
  FillOptimizerStatus(behind, later, &b);
  EXPECT_EQ(b.level, DiagnosticStatus::WARN);
  EXPECT_NE(b.message.find("falls behind: 3 window(s) dropped"), std::string::npos) << b.message;
  DiagnosticStatusWrapper steady;
  FillOptimizerStatus(behind, behind, &steady);  // none dropped during this period
  EXPECT_EQ(steady.level, DiagnosticStatus::OK);
}

TEST(MapperDiagnostics, LostInputsAreReportedWithTheQueueDepths) {
  MapperStatusSnapshot before;
  before.mask_queue_size = 10;
  before.odom_queue_size = 200;
  MapperStatusSnapshot now = before;
  now.mask_gaps.lost_by_stamp = 9;
  now.odometry_gaps.lost_by_seq = 2;
  DiagnosticStatusWrapper s;
  FillFrameStatus(now, before, InputStats(), &s);
  EXPECT_EQ(Value(s, "subscriber queue: masks"), "10");
  EXPECT_EQ(Value(s, "subscriber queue: odometry"), "200");
  EXPECT_EQ(Value(s, "masks lost before the callback (stamp gaps)"), "9");
  EXPECT_EQ(Value(s, "odometry lost before the callback (seq gaps)"), "2");
  EXPECT_EQ(s.level, DiagnosticStatus::WARN);
  DiagnosticStatusWrapper quiet;
  FillFrameStatus(now, now, InputStats(), &quiet);  // nothing new lost
  EXPECT_NE(quiet.message.find("idle"), std::string::npos) << quiet.message;
}

TEST(MapperDiagnostics, SavesShowTheLastSaveAndAFailureIsAnError) {
  DiagnosticStatusWrapper off;
  FillSaveStatus(MapSaveStatus(), 100.0, &off);
  EXPECT_EQ(off.level, DiagnosticStatus::OK);
  EXPECT_NE(off.message.find("off"), std::string::npos);

  MapSaveStatus save;
  save.path = "/tmp/live.json";
  save.autosave_period_s = 2.0;
  DiagnosticStatusWrapper none;
  FillSaveStatus(save, 100.0, &none);
  EXPECT_EQ(none.level, DiagnosticStatus::OK);
  EXPECT_EQ(Value(none, "last save wall time"), "none yet");

  save.saves = 3;
  save.last_wall_time = 1000.0;
  save.last_ok = true;
  save.last_status = "ok: 4 markings, 2 lanes to /tmp/live.json";
  DiagnosticStatusWrapper ok;
  FillSaveStatus(save, 1002.5, &ok);
  EXPECT_EQ(ok.level, DiagnosticStatus::OK);
  EXPECT_EQ(Value(ok, "path"), "/tmp/live.json");
  EXPECT_EQ(Value(ok, "last save wall time"), "1000.000");
  EXPECT_EQ(Value(ok, "last save age (s)"), "2.5");
  EXPECT_EQ(Value(ok, "last save status"), save.last_status);

  save.failures = 1;
  save.last_ok = false;
  save.last_status = "/tmp/live.json: cannot create folder: Not a directory";
  DiagnosticStatusWrapper failed;
  FillSaveStatus(save, 1003.0, &failed);
  EXPECT_EQ(failed.level, DiagnosticStatus::ERROR);
  EXPECT_NE(failed.message.find("Not a directory"), std::string::npos);
  EXPECT_EQ(Value(failed, "failures"), "1");
}

}  // namespace
}  // namespace ipm_road_mapper
