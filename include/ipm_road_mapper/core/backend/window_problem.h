// One solve of the back end over a sliding window (docs/design.md §4, paper "Map Optimization"
// and "Pose Update"): a copied snapshot of the window goes in, the optimized state comes
// out; the live map is never touched here. Each round alternates
//   1. map + extrinsic step: marking corners, lane control points, R_base_cam, t_base_cam
//      free; the window's poses constant (which also fixes the gauge: the map is anchored
//      to the odometry frame through them). Corner reprojection + PPSR (or PSR) residuals,
//      the translation prior on t_base_cam, a weak along-lane anchor per control point.
//   2. pose step: the window's poses free; map and extrinsic constant. The same residuals
//      plus a prior of each pose on its odometry. (Both at once make camera and vehicle
//      motion fight, as the paper notes.)
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "ipm_road_mapper/core/backend/backend_options.h"
#include "ipm_road_mapper/core/backend/extrinsic_prior.h"
#include "ipm_road_mapper/core/backend/pose_covariance.h"
#include "ipm_road_mapper/core/geometry/pinhole_camera.h"
#include "ipm_road_mapper/core/map/road_map.h"

namespace ipm_road_mapper {

// A frame of the window: its current pose estimate and its odometry (the prior).
struct WindowFrame {
  std::size_t index = 0;
  Eigen::Isometry3d T_map_base = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d T_map_base_odom = Eigen::Isometry3d::Identity();
  // In the window: its pose is free in the pose step. Otherwise a context frame (older
  // measurements of the window's elements were made from it): its pose is data.
  bool in_window = true;
  double stamp = 0.0;  // s (the motion prior's time steps)
  // In a result: its pose was free in the last pose step (data moved it); else it is the
  // snapshot's (no measurement in the window touched it).
  bool optimized = false;
  // The ground the front end mapped this frame's pixels onto, in base_link (FrameRecord).
  RoadPlane ground_base;
};

// A marking observed in the window, with its in-window measurements.
struct WindowMarking {
  std::uint64_t id = 0;
  std::array<Eigen::Vector3d, 4> corners_map;
  std::vector<MarkingMeasurement> measurements;
  // The road's direction at the marking (tangent of the nearest lane; zero: unknown), along
  // which its corners are re-measured.
  Eigen::Vector3d axis_map = Eigen::Vector3d::Zero();
  // Its estimate is settled (through an earlier solve, seen from near): only such a marking
  // corrects poses (a new one is where flat-ground IPM put it, meters off, and poses
  // aligned to it would drift with it).
  bool mature = false;
  // Seen only in partial views (larger than the view): its pixels refine it with the
  // extrinsic held (their pull on it was wrong on av2_pit_dev: docs/backend.md).
  bool partial_only = false;
};

// A lane observed in the window. `first_cp_index` is the lane's global index of
// control_points_map[0] (it decreases when the lane grows at its start), so a result can be
// applied to a lane that grew meanwhile.
struct WindowLane {
  std::uint64_t id = 0;
  std::int64_t first_cp_index = 0;
  std::vector<Eigen::Vector3d> control_points_map;
  std::vector<LaneMeasurement> measurements;
};

// What the front end hands to the optimizer.
struct WindowSnapshot {
  std::uint64_t sequence = 0;
  CameraIntrinsics camera;
  Eigen::Isometry3d T_base_cam = Eigen::Isometry3d::Identity();
  // What retired data (and the mounting prior) say about the extrinsic.
  ExtrinsicPrior extrinsic_prior;
  std::vector<WindowFrame> frames;  // sorted by index: the window and its context frames
  std::vector<WindowMarking> markings;
  std::vector<WindowLane> lanes;
  // Whether the result carries the Ceres covariance of the newest optimized pose (off for
  // the final global solve: its problem spans the drive).
  bool newest_pose_covariance = true;
  // Whether the refined extrinsic is cross-validated on the two halves of the frames and
  // falls back to the rough one (extrinsic_prior's center) in every direction they do not
  // confirm (window_extrinsic_validation.h; on for the final global solve).
  bool cross_validate_extrinsic = false;
  // Iterations of the joint step after the rounds (window_joint_step.h; 0: none; the final
  // global solve's BackendOptions::final_global_joint_iterations).
  int joint_step_iterations = 0;
};

// What the optimizer hands back (immutable once published).
struct WindowResult {
  std::uint64_t sequence = 0;
  bool usable = false;  // Ceres says the solution is usable and the trust bound holds
  std::string reason;   // why not usable
  Eigen::Isometry3d T_base_cam = Eigen::Isometry3d::Identity();
  std::vector<WindowFrame> frames;
  std::vector<WindowMarking> markings;  // measurements left empty
  std::vector<WindowLane> lanes;        // measurements left empty
  double extrinsic_change_rad = 0.0;
  double extrinsic_change_m = 0.0;
  // The extrinsic's calibration (extrinsic_observability.h): the covariance of T_base_cam
  // in the prior's chart (roll, pitch, yaw about base_link in rad, then x, y, z in m) and
  // which of those axes this solve's data observed (the others were held).
  Eigen::Matrix<double, 6, 6> T_base_cam_covariance = Eigen::Matrix<double, 6, 6>::Zero();
  std::array<bool, 6> extrinsic_observed{};
  int extrinsic_observed_rank = 0;  // observed eigen-directions
  // The guard: the refined extrinsic explained the held-out frames worse than the starting
  // one (their robustified costs below), so the starting one was kept.
  bool extrinsic_rejected = false;
  double holdout_cost_candidate = 0.0, holdout_cost_reference = 0.0;
  int holdout_blocks = 0;
  // The cross-validation: how many observed directions of the extrinsic it sent back to
  // the rough value (the halves of the data disagreed on them).
  int extrinsic_directions_reverted = 0;
  // The joint step (window_joint_step.h): how many directions of the extrinsic besides the
  // held lever arm its data did not observe, held where the alternation left them.
  int joint_extrinsic_held = 0;
  double solve_time_s = 0.0;
  int residual_blocks = 0;
  int iterations = 0;
  double initial_cost = 0.0, final_cost = 0.0;
  std::string summary;  // Ceres BriefReport of the last step
  // The covariance of the newest optimized frame's pose after the last pose step
  // (pose_covariance.h); covariance_frame is that frame's index, -1 when not computed.
  std::int64_t covariance_frame = -1;
  PoseCovariance T_map_base_covariance = PoseCovariance::Zero();
};

// Builds and solves the window's alternating problem. With a finite time_budget_s, each
// Ceres step gets what is left of it and no step starts after it has run out (the result is
// then that of the steps that ran).
WindowResult SolveWindow(const WindowSnapshot& snapshot, const BackendOptions& options,
                         double time_budget_s = std::numeric_limits<double>::infinity());

}  // namespace ipm_road_mapper
