// The Mapper <-> Backend wiring: windows go to the optimizer and come back into the map
// (poses, markings, lanes), a result lands on the right control points of a lane that grew
// at its start meanwhile (index offsets), markings that leave the window retire, and the
// end of input runs the final global solve. Synchronous back end: deterministic.
#include <gtest/gtest.h>

#include <chrono>

#include "common/road_scene.h"
#include "ipm_road_mapper/core/frontend/instance_extraction.h"
#include "ipm_road_mapper/core/mapper/lane_tracker.h"
#include "ipm_road_mapper/core/mapper/marking_tracker.h"
#include "ipm_road_mapper/core/mapper/window_coordinator.h"

namespace ipm_road_mapper {
namespace {

using namespace test;  // NOLINT: the scene's helpers

MapperOptions SynchronousOptions() {
  MapperOptions options;
  options.backend.enabled = true;
  options.backend.synchronous = true;
  options.backend.window_frames = 20;
  options.backend.solve_every_n_frames = 5;
  return options;
}

// The Mapper's rooms, wired as the Mapper wires them, so a test can act between a window's
// submission and the merge of its result.
struct Rig : RoomRig {
  explicit Rig(MapperOptions o) : RoomRig(std::move(o)) {}
  // One frame through the front end; true when the coordinator submitted a window.
  bool Step(const FrameInput& in) {
    windows.ApplyResults();
    std::optional<Ipm> ipm;
    FrameObservations obs = Observe(in, windows.T_base_cam(), &ipm);
    const FrameRecord& frame = store.AddFrame(in.stamp, in.T_map_base_odom);
    markings.Update(*ipm, frame, &obs.markings);
    lanes.Update(obs.lanes, frame);
    ++counters.frames_used;
    const std::uint64_t solved = windows.stats().submitted;
    windows.OnFrameUsed(counters.frames_used, in.camera);
    return windows.stats().submitted > solved;
  }
  MarkingTracker markings{options, &store, &counters};
  LaneTracker lanes{options, &store, &counters};
  WindowCoordinator windows{options, TestExtrinsic(), &store, &counters};
};

// A frame whose odometry is off by a slowly growing offset, so that results move poses.
FrameInput DriftingFrame(int k) {
  FrameInput in = RoadFrame(100.0 + 0.05 * k, 0.5 * k);
  in.T_map_base_odom.translation().y() += 0.002 * k;
  return in;
}

TEST(WindowCoordinator, ResultsComeBackIntoTheMap) {
  Rig rig(SynchronousOptions());
  for (int k = 0; k < 30; ++k) rig.Step(DriftingFrame(k));
  rig.windows.ApplyResults();
  EXPECT_GE(rig.counters.results_applied, 5u);
  EXPECT_EQ(rig.windows.stats().solved, rig.windows.stats().submitted);
  ASSERT_EQ(rig.store.markings().size(), 1u);
  EXPECT_TRUE(rig.store.markings()[0].optimized);
  ASSERT_EQ(rig.store.lanes().size(), 1u);
  EXPECT_TRUE(rig.store.lanes()[0].optimized);
  // Poses in the last window were corrected: no longer the odometry.
  const FrameRecord& last = rig.store.frames()[25];
  EXPECT_FALSE(last.T_map_base.isApprox(last.T_map_base_odom, 1e-9));
  // The refined extrinsic is fed forward.
  EXPECT_FALSE(rig.windows.T_base_cam().isApprox(TestExtrinsic(), 1e-12));
}

// The last solve's correction comes out on the frames after it: a frame added after a solve
// comes out at the correction times its odometry (not at the raw odometry), the correction
// is fitted over the frames the solve moved, and the covariance handed out for the new
// frame is the solved one carried along plus the frame's own odometry noise.
TEST(WindowCoordinator, FramesAfterASolveComeOutWithItsCorrection) {
  Rig rig(SynchronousOptions());
  int k = 0;
  while (rig.counters.results_applied < 3) {
    rig.Step(DriftingFrame(k++));
    rig.windows.ApplyResults();
  }
  const Eigen::Isometry3d T_map_odom = rig.store.T_map_odom();
  EXPECT_FALSE(T_map_odom.isApprox(Eigen::Isometry3d::Identity(), 1e-6));  // it did correct
  // The correction is fitted over the frames the solve moved (odometry_correction.h): it
  // is theirs, and carries the newest of them to its solved pose within its odometry noise.
  ASSERT_GE(rig.store.corrected_frame(), 0);
  const FrameRecord& solved = rig.store.frames()[rig.store.corrected_frame()];
  EXPECT_FALSE(solved.T_map_base.isApprox(solved.T_map_base_odom, 1e-9));
  const Eigen::Vector3d carried = (T_map_odom * solved.T_map_base_odom).translation();
  EXPECT_LT((carried - solved.T_map_base.translation()).head<2>().norm(),
            3.0 * rig.options.backend.pose_prior_sigma_trans_m.head<2>().norm());
  // A frame after the solve comes out with the correction carried along its odometry.
  ASSERT_FALSE(rig.Step(DriftingFrame(k++)));  // no window submitted: no new correction
  const FrameRecord& added = rig.store.frames().back();
  const Eigen::Isometry3d T_out = rig.store.CorrectedPose(added.index);
  EXPECT_TRUE(T_out.isApprox(T_map_odom * added.T_map_base_odom, 1e-12));
  EXPECT_FALSE(T_out.isApprox(added.T_map_base_odom, 1e-6));
  const PoseCovariance covariance = rig.windows.PoseCovarianceOf(added.index);
  EXPECT_TRUE(covariance.allFinite());
  EXPECT_TRUE(covariance.isApprox(covariance.transpose(), 1e-9));
  EXPECT_GT(covariance.ldlt().vectorD().minCoeff(), 0.0);
  // At least the new frame's own odometry noise (the solved part adds to it).
  const BackendOptions& o = rig.options.backend;
  const PoseCovariance odometry =
      OdometryPoseCovariance(T_out, o.pose_prior_sigma_trans_m, o.pose_prior_sigma_rot_rad);
  EXPECT_GT((covariance - odometry).diagonal().minCoeff(), 0.0);
}

// Two identical runs; in the second, the lane gains a control point at its start between a
// window's submission and the merge of its result. The result must land on the same points
// (shifted by one), and the new point must stay as it is.
TEST(WindowCoordinator, ResultLandsOnTheRightControlPointsOfAGrownLane) {
  Rig plain(SynchronousOptions()), grown(SynchronousOptions());
  int k = 0;
  for (; k < 200; ++k) {
    plain.Step(DriftingFrame(k));
    const bool submitted = grown.Step(DriftingFrame(k));
    if (submitted && !grown.store.lanes().empty() && grown.store.lanes()[0].optimized) break;
  }
  ASSERT_LT(k, 200);
  LaneElement& lane = grown.store.lanes()[0];
  const std::vector<Eigen::Vector3d> before = lane.control_points_map;
  const Eigen::Vector3d added = before[0] - (before[1] - before[0]);
  lane.control_points_map.insert(lane.control_points_map.begin(), added);
  lane.first_cp_index -= 1;
  plain.windows.ApplyResults();
  grown.windows.ApplyResults();
  const auto& p = plain.store.lanes()[0].control_points_map;
  const auto& g = grown.store.lanes()[0].control_points_map;
  ASSERT_EQ(g.size(), p.size() + 1);
  EXPECT_EQ(g[0], added);
  // The old first point was a phantom end in the snapshot: the result's value is not
  // applied to it (it is a real point now).
  EXPECT_EQ(g[1], before[0]);
  bool moved = false;
  for (std::size_t i = 1; i + 1 < p.size(); ++i) {
    EXPECT_TRUE(g[i + 1].isApprox(p[i], 1e-12)) << i;
    moved = moved || !p[i].isApprox(before[i], 1e-9);
  }
  EXPECT_TRUE(moved);  // the result did change the lane
}

TEST(WindowCoordinator, MarkingsRetireAndTheFinalSolveRuns) {
  Rig rig(SynchronousOptions());
  for (int k = 0; k < 80; ++k) rig.Step(DriftingFrame(k));  // the arrow is passed at k ~ 40
  // The arrow left the window: retired, out of the live markings.
  EXPECT_TRUE(rig.store.markings().empty());
  ASSERT_EQ(rig.store.retired_markings().size(), 1u);
  EXPECT_TRUE(rig.store.retired_markings()[0].retired);
  rig.windows.ApplyResults();  // the window submitted by the last frame
  const std::uint64_t applied = rig.counters.results_applied;
  rig.windows.Finish();
  // The last window and the global solve.
  EXPECT_EQ(rig.counters.results_applied, applied + 2);
}

TEST(WindowCoordinator, TheGlobalSolveStartsAtTheMountingExtrinsic) {
  // The windows refine the extrinsic along their path; the drive's batch solve starts at its
  // prior's center, the mounting value, unless told to start where the windows left it.
  MapperOptions options = SynchronousOptions();
  Rig rig(options);
  for (int k = 0; k < 80; ++k) rig.Step(DriftingFrame(k));
  rig.windows.ApplyResults();
  ASSERT_FALSE(rig.windows.T_base_cam().isApprox(TestExtrinsic(), 1e-9));
  const WindowSnapshot global = rig.windows.BuildGlobalSnapshot();
  EXPECT_TRUE(global.T_base_cam.isApprox(TestExtrinsic(), 1e-12));
  EXPECT_TRUE(global.extrinsic_prior.DeltaOf(TestExtrinsic()).isZero(1e-12));
  EXPECT_TRUE(global.cross_validate_extrinsic);
  EXPECT_EQ(global.joint_step_iterations, options.backend.final_global_joint_iterations);

  options.backend.final_global_from_mounting = false;
  Rig from_windows(options);
  for (int k = 0; k < 80; ++k) from_windows.Step(DriftingFrame(k));
  from_windows.windows.ApplyResults();
  EXPECT_TRUE(from_windows.windows.BuildGlobalSnapshot().T_base_cam.isApprox(
      from_windows.windows.T_base_cam(), 1e-12));
}

TEST(WindowCoordinator, FinishKeepsItsTimeBudget) {
  MapperOptions options = SynchronousOptions();
  options.backend.synchronous = false;  // a real optimizer thread, as on a vehicle
  Rig rig(options);
  for (int k = 0; k < 60; ++k) rig.Step(DriftingFrame(k));
  const auto start = std::chrono::steady_clock::now();
  rig.windows.Finish(0.0);  // nothing may be waited for
  const double took_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_LT(took_s, 0.5);  // one snapshot, no solve waited for (a window solve takes ~50 ms)
  Rig unbounded(SynchronousOptions());
  for (int k = 0; k < 60; ++k) unbounded.Step(DriftingFrame(k));
  EXPECT_TRUE(unbounded.windows.Finish());
}

TEST(WindowCoordinator, WithoutBackendMarkingsRetireToo) {
  MapperOptions options = SynchronousOptions();
  options.backend.enabled = false;
  Rig rig(options);
  for (int k = 0; k < 80; ++k) rig.Step(DriftingFrame(k));
  EXPECT_TRUE(rig.store.markings().empty());
  EXPECT_EQ(rig.store.retired_markings().size(), 1u);
}

TEST(WindowCoordinator, WithoutBackendNothingIsSubmitted) {
  MapperOptions options = SynchronousOptions();
  options.backend.enabled = false;
  Rig rig(options);
  for (int k = 0; k < 12; ++k) EXPECT_FALSE(rig.Step(DriftingFrame(k)));
  rig.windows.Finish();
  EXPECT_FALSE(rig.windows.enabled());
  EXPECT_EQ(rig.counters.results_applied, 0u);
  EXPECT_TRUE(rig.windows.T_base_cam().isApprox(TestExtrinsic()));
}

}  // namespace
}  // namespace ipm_road_mapper
