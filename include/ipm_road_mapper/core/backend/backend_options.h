// Options of the back end (config section `backend`): what is optimized, the residual
// weights and robust kernel, the sliding window, the alternation and the trust bound. The
// ablation rows of the paper are combinations of these switches (config/ablations/).
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>

#include "ipm_road_mapper/core/io/yaml_options.h"

namespace ipm_road_mapper {

// How lane control points are refined.
enum class LaneResidual {
  kNone,  // not optimized: control points re-estimated by g from re-IPMed selected points
  kPsr,   // point-to-spline residual on IPM points (ablation)
  kPpsr,  // projected point-to-spline residual on pixels (the paper's method)
};

// The config string of a lane residual: "none", "psr" or "ppsr".
const char* ToString(LaneResidual residual);

// The robust kernel on the measurement residuals (corners, PPSR, PSR).
enum class RobustKernel {
  kHuber,   // ceres::HuberLoss
  kCauchy,  // ceres::CauchyLoss
  kNone,    // plain least squares
};

// The config string of a robust kernel: "huber", "cauchy" or "none".
const char* ToString(RobustKernel kernel);

// The kernel named by `name` ("huber", "cauchy", "none"); nullopt for any other string.
std::optional<RobustKernel> ParseRobustKernel(const std::string& name);

// Every option of the back end, with its default.
struct BackendOptions {
  bool enabled = true;             // false: plain IPM front end only
  bool synchronous = false;        // solve in the caller's thread (offline determinism)
  bool optimize_extrinsic = true;  // R_base_cam, t_base_cam free in the map step
  bool optimize_markings = true;   // marking corners free in the map step
  bool optimize_z = true;          // z of corners and control points free
  bool pose_update = true;         // run the pose-update step
  LaneResidual lane_residual = LaneResidual::kPpsr;
  int window_frames = 40;        // frames whose observations enter a solve
  int solve_every_n_frames = 5;  // how often the front end hands a window over
  int rounds = 2;                // map+extrinsic <-> pose alternations per solve
  int max_iterations = 10;       // Ceres iterations per step
  int queue_size = 2;            // windows waiting for the optimizer thread
  double pixel_sigma_px = 2.0;   // corner and PPSR measurement sigma
  double psr_sigma_m = 0.2;      // PSR (3D) measurement sigma
  RobustKernel robust_kernel = RobustKernel::kHuber;
  double robust_scale = 2.0;  // kernel scale in whitened units (sigmas)
  Eigen::Vector3d translation_prior_sigma_m{0.02, 0.02, 0.02};
  // Prior of the extrinsic rotation on its rough value, per base_link axis (roll, pitch,
  // yaw): roll is unobservable on straight roads, pitch and yaw are observable.
  Eigen::Vector3d rotation_prior_sigma_rad{0.1 * M_PI / 180.0, 3.0 * M_PI / 180.0,
                                           3.0 * M_PI / 180.0};
  Eigen::Vector3d pose_prior_sigma_trans_m{0.3, 0.3, 0.05};        // base_link x, y, z
  Eigen::Vector3d pose_prior_sigma_rot_rad{0.001, 0.001, 0.0052};  // roll, pitch, yaw
  double max_extrinsic_change_rad = 2.0 * M_PI / 180.0;            // trust bound per solve
  double max_extrinsic_change_m = 0.2;
  // Observability of the extrinsic (extrinsic_observability.h): a direction is observed
  // when the solve's data knows it at least this many times better than the mounting prior
  // (an eigenvalue of the prior-whitened information). It decides the calibration's
  // observed flags and covariance, and, with extrinsic_hold_unobserved, the update: each
  // unobserved direction is held at the solve's starting value (off by default: on the
  // benchmark drives it stops the x/y lever arm wandering but costs rotation accuracy on
  // hilly, port and av2_pit_dev; docs/backend.md).
  double extrinsic_min_information_ratio = 4.0;
  bool extrinsic_hold_unobserved = false;
  // Memory of the retired markings' information in the extrinsic prior, in markings: each
  // retiring marking scales what is there by 1 - 1 / N (extrinsic_prior.h); 0: a plain sum.
  // A plain sum held the windows' lever arm wherever it had wandered: on the 10 km drive its y
  // walked to -0.09 m (true 0) and the lanes with it (docs/backend.md, "What leaves the
  // window").
  double extrinsic_prior_memory_markings = 50.0;
  // The guard against harm: every N-th frame's measurements are left out of the first map
  // step, and a refined extrinsic that explains them worse than the previous one (with the
  // map re-fit to each) by more than extrinsic_holdout_sigmas times the spread of the
  // per-measurement differences is refused: the previous one stays. N = 0: off. Sigmas 0:
  // only an extrinsic that explains them at least as well is kept.
  int extrinsic_holdout_every_n_frames = 0;
  double extrinsic_holdout_sigmas = 2.0;
  int max_lane_points_per_observation = 6;  // PPSR/PSR pixels per lane observation
  // A lane pixel whose IPM point is farther than this from its spline is not used.
  double max_lane_pixel_distance_m = 1.5;
  // true: a lane pixel's segment is where its ray meets the lane's own surface, not where
  // flat-ground IPM in the viewing frame's plane puts it (window_measurements.h; opt-in,
  // docs/backend.md "The roll on hills": hilly's roll 0.59 -> 0.33 deg, av2_pit_dev's lane
  // APE 0.15 -> 0.26 m).
  bool lane_pixels_on_lane_surface = false;
  // A measurement whose projection at the start of a solve is farther than this outside the
  // image (an association outlier, or a point behind the camera) is not added.
  double max_outside_image_px = 100.0;
  int max_measurements_per_marking = 10;  // observations of a marking per solve (spread)
  // Road-surface prior of free map points (with optimize_z): the height of a point in
  // base_link of the window frame horizontally closest to it is ~0, with sigma
  // hypot(road_height_sigma_m, road_height_sigma_per_m * distance). base_link's origin is on
  // the road, so the road is known at the wheels and less so ahead of them (grade, waves).
  // Without it a lane seen from a camera driving along it slides freely in the plane
  // through the camera path (height against lateral offset), and the extrinsic roll about
  // the direction of travel is unobservable.
  double road_height_sigma_m = 0.02;
  double road_height_sigma_per_m = 0.01;
  // The road's cross-section beyond the own lane (road_cross_section_prior_residual.h): a
  // point more than road_crown_lateral_m across from that frame may lie on a plane whose
  // slope differs from the body's by kappa, one kappa per side and solve, itself held by a
  // zero-mean prior of this sigma (m/m). 0: off, every point on the body's plane (the planar
  // road of the synthetic drives). Real carriageways fall 1.5-2.5 % each way from a crown
  // at a lane line, so the lines across it lie below the body's plane (docs/backend.md).
  double road_crown_slope_sigma = 0.0;
  double road_crown_lateral_m = 2.0;
  // The road's plane at a point averages the frames that drove within this radius of it
  // (road_surface.h: the body's pitch oscillation averages out over a period, ~10 m).
  double road_plane_radius_m = 6.0;
  // Anchor of each free lane control point to its value at the start of a solve
  // (along_lane_anchor_residual.h): tight along the lane (PPSR leaves that free), loose
  // across it.
  double lane_anchor_along_sigma_m = 0.05;
  double lane_anchor_across_sigma_m = 0.5;
  // Second differences of consecutive control points (lane_smoothness_residual.h); 0: off.
  double lane_smoothness_sigma_m = 0.2;
  // The map + extrinsic step weighs each measurement with the pixel sigma and the frame's
  // pose uncertainty: the pose prior's sigmas times this (0: poses taken as exact).
  double map_step_pose_sigma_scale = 0.3;
  // Motion prior of the pose step (motion_prior_residual.h): finite-difference accelerations
  // of consecutive poses, per base_link axis.
  bool motion_prior = true;
  Eigen::Vector3d motion_sigma_acc_mps2{1.0, 1.0, 2.0};            // x y z
  Eigen::Vector3d motion_sigma_angular_acc_radps2{0.5, 0.5, 0.2};  // roll pitch yaw
  // At the end of input, one solve over the last final_global_max_frames frames (the whole
  // of a shorter drive; Mapper::Finish), final_global_rounds alternations. Measurements
  // older than that span are pruned from the elements' histories: nothing reads them again.
  bool final_global_solve = true;
  int final_global_max_frames = 1500;
  int final_global_rounds = 3;
  // The global solve samples at least this many measurements per marking (windows use
  // max_measurements_per_marking): it sees each marking's whole history at once.
  int final_global_min_measurements_per_marking = 30;
  // After its rounds, the global solve's joint step (window_joint_step.h): map, extrinsic
  // (its lever arm x, y held) and poses free in one problem, at most this many iterations;
  // 0 = off (docs/backend.md, "The joint step").
  int final_global_joint_iterations = 50;
  // true: the global solve's extrinsic starts at the mounting value (the center of its
  // prior, input.extrinsic), not where the windows left it. The batch estimate of the drive's
  // calibration then does not inherit the online path's (docs/backend.md, "Where the global
  // solve starts"); its map and poses still start from the windows'.
  bool final_global_from_mounting = true;
};

// Reads the `backend` section; throws OptionsError naming the bad key.
BackendOptions LoadBackendOptions(OptionsReader reader);

// The options as `backend.<key>: <value>` lines, in config units (degrees), for the start-up
// dump.
std::string ToString(const BackendOptions& options);

}  // namespace ipm_road_mapper
