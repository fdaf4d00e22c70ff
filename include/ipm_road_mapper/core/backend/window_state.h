// Internal to SolveWindow (window_problem.h): the mutable state of one window solve, the
// measurements that survived the build-time checks, and the helpers every step shares.
// Split by step: window_measurements.h (collecting them), window_map_step.h (map +
// extrinsic step), window_pose_step.h (pose step), window_extrinsic.h (observability, the
// guard, the calibration).
#pragma once

#include <ceres/ceres.h>

#include <Eigen/Geometry>
#include <array>
#include <limits>
#include <map>
#include <vector>

#include "ipm_road_mapper/core/backend/backend_options.h"
#include "ipm_road_mapper/core/backend/extrinsic_observability.h"
#include "ipm_road_mapper/core/backend/pose_covariance.h"
#include "ipm_road_mapper/core/backend/window_problem.h"
#include "ipm_road_mapper/core/geometry/pinhole_camera.h"

namespace ipm_road_mapper {
namespace window_solve {

// A rigid transform as Ceres parameter blocks: quaternion (x, y, z, w) and translation.
struct PoseBlocks {
  double q[4];
  double t[3];
  explicit PoseBlocks(const Eigen::Isometry3d& T) {
    Eigen::Map<Eigen::Quaterniond> q_map(q);
    q_map = Eigen::Quaterniond(T.linear()).normalized();
    Eigen::Map<Eigen::Vector3d> t_map(t);
    t_map = T.translation();
  }
  Eigen::Isometry3d ToIsometry() const {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::Map<const Eigen::Quaterniond>(q).normalized().toRotationMatrix();
    T.translation() = Eigen::Map<const Eigen::Vector3d>(t);
    return T;
  }
};

// One marking corner measurement: which marking, corner and frame slot.
struct CornerMeasurement {
  std::size_t marking = 0;
  int corner = 0;
  std::size_t slot = 0;
  Eigen::Vector2d uv;
};

// One pixel on a measured side of a partial view whose corner the view cut (the edge
// residual): which marking, side (corners side and side + 1) and frame slot.
struct EdgeMeasurement {
  std::size_t marking = 0;
  int side = 0;
  std::size_t slot = 0;
  Eigen::Vector2d uv;
};

// One lane pixel: which lane, frame slot and spline segment (the segment's control points
// are c[segment] .. c[segment + 3]; PPSR uses c[segment + 1], c[segment + 2]).
struct LanePixel {
  std::size_t lane = 0;
  std::size_t slot = 0;
  Eigen::Vector2d uv;
  int segment = 0;
  double u = 0.0;
  Eigen::Vector3d q_map;   // IPM point at build time (PSR)
  Eigen::Vector3d p_base;  // the same point in its frame's base_link (PSR, joint step)
};

// The mutable state of one solve, initialized from the snapshot, and the measurements that
// survived the build-time checks.
struct WindowState {
  PoseBlocks extrinsic;
  std::vector<PoseBlocks> frames;
  std::map<std::size_t, std::size_t> slot_of_frame;
  std::vector<std::array<Eigen::Vector3d, 4>> corners;
  std::vector<std::vector<Eigen::Vector3d>> control_points;
  std::vector<CornerMeasurement> corner_measurements;
  std::vector<EdgeMeasurement> edge_measurements;
  PoseBlocks held_extrinsic;  // the extrinsic as partial-only markings see it (held)
  // The road's slope change beyond the own lane, left and right of the vehicle
  // (BackendOptions::road_crown_slope_sigma; road_cross_section_prior_residual.h).
  std::array<double, 2> crown_slope{{0.0, 0.0}};
  std::vector<LanePixel> lane_pixels;
  std::vector<Eigen::Isometry3d> poses;  // the frames' poses at the start (road surface)
  std::vector<bool> optimized;           // free in a pose step (WindowFrame::optimized)
  int covariance_slot = -1;              // the newest optimized frame after the last pose step
  PoseCovariance covariance = PoseCovariance::Zero();                  // of that frame's pose
  double step_time_limit_s = std::numeric_limits<double>::infinity();  // of the next step
  // The extrinsic guard (BackendOptions::extrinsic_holdout_every_n_frames): the frames whose
  // measurements the map step leaves out while `hold_out` is set, and whether the
  // extrinsic is held at its value (the guard's reference fit, or after a rejection).
  std::vector<bool> held_out;
  bool hold_out = false;
  bool extrinsic_frozen = false;
  // What the last map step with the extrinsic free found about it.
  ExtrinsicObservability observability;
  bool observability_valid = false;
  explicit WindowState(const WindowSnapshot& s)
      : extrinsic(s.T_base_cam), held_extrinsic(s.T_base_cam) {
    for (std::size_t i = 0; i < s.frames.size(); ++i) {
      frames.emplace_back(s.frames[i].T_map_base);
      poses.push_back(s.frames[i].T_map_base);
      slot_of_frame[s.frames[i].index] = i;
      held_out.push_back(false);
    }
    optimized.assign(s.frames.size(), false);
    for (const WindowMarking& m : s.markings) corners.push_back(m.corners_map);
    for (const WindowLane& l : s.lanes) control_points.push_back(l.control_points_map);
  }
};

// True when p_map projects in front of the camera of `slot`, at most margin_px outside the
// image (BackendOptions::max_outside_image_px).
bool ProjectsNearImage(const PinholeCamera& camera, const WindowState& state, std::size_t slot,
                       const Eigen::Vector3d& p_map, double margin_px);

// The odometry prior of every window frame whose pose is in `problem` (PosePriorResidual on
// T_map_base_odom, pose_prior_sigma_*), its rotation on the quaternion manifold; a context
// frame's pose (not in_window) is held constant instead (data).
void AddPosePriors(const WindowSnapshot& snapshot, const BackendOptions& options,
                   WindowState* state, ceres::Problem* problem);

// Which consecutive triples of frames (by index) get the motion prior (AddMotionPriors).
enum class MotionPriorTriples {
  kMiddleInProblem,  // the middle pose is in the problem; the other two join (pose step)
  kAllInProblem,     // all three poses are in the problem and the middle one is in the window
};

// The motion prior (MotionPriorResidual, motion_sigma_*) over the triples `triples` selects;
// nothing without options.motion_prior.
void AddMotionPriors(const WindowSnapshot& snapshot, const BackendOptions& options,
                     MotionPriorTriples triples, WindowState* state, ceres::Problem* problem);

// The robust kernel of the measurement residuals (BackendOptions::robust_kernel); nullptr
// for none. The problem it is given to owns it.
ceres::LossFunction* MakeLoss(const BackendOptions& options);

// Solves one step (Levenberg-Marquardt, sparse normal Cholesky, at most max_iterations and
// time_limit_s); an empty problem gives an empty summary.
ceres::Solver::Summary Solve(const BackendOptions& options, double time_limit_s,
                             ceres::Problem* problem);

}  // namespace window_solve
}  // namespace ipm_road_mapper
