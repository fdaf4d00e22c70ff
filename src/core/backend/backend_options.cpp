#include "ipm_road_mapper/core/backend/backend_options.h"

#include <cmath>
#include <sstream>
#include <vector>

namespace ipm_road_mapper {

const char* ToString(LaneResidual residual) {
  switch (residual) {
    case LaneResidual::kPsr:
      return "psr";
    case LaneResidual::kPpsr:
      return "ppsr";
    default:
      return "none";
  }
}

const char* ToString(RobustKernel kernel) {
  switch (kernel) {
    case RobustKernel::kHuber:
      return "huber";
    case RobustKernel::kCauchy:
      return "cauchy";
    case RobustKernel::kNone:
      return "none";
  }
  return "none";
}

std::optional<RobustKernel> ParseRobustKernel(const std::string& name) {
  for (RobustKernel kernel : {RobustKernel::kHuber, RobustKernel::kCauchy, RobustKernel::kNone}) {
    if (name == ToString(kernel)) return kernel;
  }
  return std::nullopt;
}

namespace {

constexpr double kDegToRad = M_PI / 180.0;

std::string CheckPositiveTriple(const std::vector<double>& v) {
  if (v.size() != 3) return "must have 3 values";
  for (double x : v) {
    if (!std::isfinite(x) || x <= 0.0) return "values must be finite and > 0";
  }
  return "";
}

Eigen::Vector3d ReadTriple(OptionsReader* reader, const std::string& key,
                           const Eigen::Vector3d& default_value, double scale) {
  std::vector<double> v{default_value.x() / scale, default_value.y() / scale,
                        default_value.z() / scale};
  reader->Read<std::vector<double>>(key, &v, CheckPositiveTriple);
  return Eigen::Vector3d(v[0], v[1], v[2]) * scale;
}

}  // namespace

BackendOptions LoadBackendOptions(OptionsReader reader) {
  BackendOptions o;
  reader.Read<bool>("enabled", &o.enabled);
  reader.Read<bool>("synchronous", &o.synchronous);
  reader.Read<bool>("optimize_extrinsic", &o.optimize_extrinsic);
  reader.Read<bool>("optimize_markings", &o.optimize_markings);
  reader.Read<bool>("optimize_z", &o.optimize_z);
  reader.Read<bool>("pose_update", &o.pose_update);
  std::string lane_residual = ToString(o.lane_residual);
  reader.Read<std::string>("lane_residual", &lane_residual, [](const std::string& v) {
    return v == "none" || v == "psr" || v == "ppsr" ? "" : "must be none, psr or ppsr";
  });
  o.lane_residual = lane_residual == "ppsr"  ? LaneResidual::kPpsr
                    : lane_residual == "psr" ? LaneResidual::kPsr
                                             : LaneResidual::kNone;
  reader.Read<int>("window_frames", &o.window_frames, CheckPositiveInt);
  reader.Read<int>("solve_every_n_frames", &o.solve_every_n_frames, CheckPositiveInt);
  if (o.solve_every_n_frames > o.window_frames) {  // frames between two windows: never solved
    throw OptionsError(reader.KeyPath("solve_every_n_frames") + ": must be <= window_frames (" +
                       std::to_string(o.window_frames) + "), got " +
                       std::to_string(o.solve_every_n_frames));
  }
  reader.Read<int>("rounds", &o.rounds, CheckPositiveInt);
  reader.Read<int>("max_iterations", &o.max_iterations, CheckPositiveInt);
  reader.Read<int>("queue_size", &o.queue_size, CheckPositiveInt);
  reader.Read<double>("pixel_sigma_px", &o.pixel_sigma_px, CheckPositive);
  reader.Read<double>("psr_sigma_m", &o.psr_sigma_m, CheckPositive);
  std::string robust_kernel = ToString(o.robust_kernel);
  reader.Read<std::string>("robust_kernel", &robust_kernel, [](const std::string& v) {
    return ParseRobustKernel(v) ? "" : "must be huber, cauchy or none";
  });
  o.robust_kernel = *ParseRobustKernel(robust_kernel);
  reader.Read<double>("robust_scale", &o.robust_scale, CheckPositive);
  o.translation_prior_sigma_m =
      ReadTriple(&reader, "translation_prior_sigma_m", o.translation_prior_sigma_m, 1.0);
  o.rotation_prior_sigma_rad =
      ReadTriple(&reader, "rotation_prior_sigma_deg", o.rotation_prior_sigma_rad, kDegToRad);
  o.pose_prior_sigma_trans_m =
      ReadTriple(&reader, "pose_prior_sigma_trans_m", o.pose_prior_sigma_trans_m, 1.0);
  o.pose_prior_sigma_rot_rad =
      ReadTriple(&reader, "pose_prior_sigma_rot_deg", o.pose_prior_sigma_rot_rad, kDegToRad);
  double max_change_deg = o.max_extrinsic_change_rad / kDegToRad;
  reader.Read<double>("max_extrinsic_change_deg", &max_change_deg, CheckPositive);
  o.max_extrinsic_change_rad = max_change_deg * kDegToRad;
  reader.Read<double>("max_extrinsic_change_m", &o.max_extrinsic_change_m, CheckPositive);
  reader.Read<double>("extrinsic_min_information_ratio", &o.extrinsic_min_information_ratio,
                      CheckNonNegative);
  reader.Read<bool>("extrinsic_hold_unobserved", &o.extrinsic_hold_unobserved);
  reader.Read<double>(
      "extrinsic_prior_memory_markings", &o.extrinsic_prior_memory_markings, [](const double& v) {
        return v == 0.0 || (std::isfinite(v) && v >= 1.0) ? "" : "must be 0 or >= 1";
      });
  reader.Read<int>("extrinsic_holdout_every_n_frames", &o.extrinsic_holdout_every_n_frames,
                   [](const int& v) { return v == 0 || v >= 2 ? "" : "must be 0 or >= 2"; });
  reader.Read<double>("extrinsic_holdout_sigmas", &o.extrinsic_holdout_sigmas, CheckNonNegative);
  reader.Read<int>("max_lane_points_per_observation", &o.max_lane_points_per_observation,
                   CheckPositiveInt);
  reader.Read<double>("max_lane_pixel_distance_m", &o.max_lane_pixel_distance_m, CheckPositive);
  reader.Read<bool>("lane_pixels_on_lane_surface", &o.lane_pixels_on_lane_surface);
  reader.Read<double>("max_outside_image_px", &o.max_outside_image_px, CheckNonNegative);
  reader.Read<int>("max_measurements_per_marking", &o.max_measurements_per_marking,
                   [](const int& v) { return v >= 2 ? "" : "must be >= 2"; });
  reader.Read<double>("road_height_sigma_m", &o.road_height_sigma_m, CheckPositive);
  reader.Read<double>("road_height_sigma_per_m", &o.road_height_sigma_per_m, CheckNonNegative);
  reader.Read<double>("road_crown_slope_sigma", &o.road_crown_slope_sigma, CheckNonNegative);
  reader.Read<double>("road_crown_lateral_m", &o.road_crown_lateral_m, CheckPositive);
  reader.Read<double>("road_plane_radius_m", &o.road_plane_radius_m, CheckNonNegative);
  reader.Read<double>("lane_anchor_along_sigma_m", &o.lane_anchor_along_sigma_m, CheckPositive);
  reader.Read<double>("lane_anchor_across_sigma_m", &o.lane_anchor_across_sigma_m, CheckPositive);
  reader.Read<double>("lane_smoothness_sigma_m", &o.lane_smoothness_sigma_m, CheckNonNegative);
  reader.Read<bool>("motion_prior", &o.motion_prior);
  o.motion_sigma_acc_mps2 =
      ReadTriple(&reader, "motion_sigma_acc_mps2", o.motion_sigma_acc_mps2, 1.0);
  o.motion_sigma_angular_acc_radps2 = ReadTriple(&reader, "motion_sigma_angular_acc_radps2",
                                                 o.motion_sigma_angular_acc_radps2, 1.0);
  reader.Read<bool>("final_global_solve", &o.final_global_solve);
  reader.Read<double>("map_step_pose_sigma_scale", &o.map_step_pose_sigma_scale, CheckNonNegative);
  reader.Read<int>("final_global_max_frames", &o.final_global_max_frames, CheckPositiveInt);
  reader.Read<int>("final_global_rounds", &o.final_global_rounds, CheckPositiveInt);
  reader.Read<int>("final_global_min_measurements_per_marking",
                   &o.final_global_min_measurements_per_marking, CheckPositiveInt);
  reader.Read<int>("final_global_joint_iterations", &o.final_global_joint_iterations,
                   [](const int& v) { return v >= 0 ? "" : "must be >= 0"; });
  reader.Read<bool>("final_global_from_mounting", &o.final_global_from_mounting);
  reader.RejectUnknownKeys();
  return o;
}

namespace {

// `[x, y, z]` of v / scale.
std::string Triple(const Eigen::Vector3d& v, double scale) {
  std::ostringstream s;
  s << "[" << v.x() / scale << ", " << v.y() / scale << ", " << v.z() / scale << "]";
  return s.str();
}

const char* Bool(bool value) { return value ? "true" : "false"; }

}  // namespace

std::string ToString(const BackendOptions& o) {
  std::ostringstream s;
  const char* k = "backend.";
  s << k << "enabled: " << Bool(o.enabled) << "\n"
    << k << "synchronous: " << Bool(o.synchronous) << "\n"
    << k << "optimize_extrinsic: " << Bool(o.optimize_extrinsic) << "\n"
    << k << "optimize_markings: " << Bool(o.optimize_markings) << "\n"
    << k << "optimize_z: " << Bool(o.optimize_z) << "\n"
    << k << "pose_update: " << Bool(o.pose_update) << "\n"
    << k << "lane_residual: " << ToString(o.lane_residual) << "\n"
    << k << "window_frames: " << o.window_frames << "\n"
    << k << "solve_every_n_frames: " << o.solve_every_n_frames << "\n"
    << k << "rounds: " << o.rounds << "\n"
    << k << "max_iterations: " << o.max_iterations << "\n"
    << k << "queue_size: " << o.queue_size << "\n"
    << k << "pixel_sigma_px: " << o.pixel_sigma_px << "\n"
    << k << "psr_sigma_m: " << o.psr_sigma_m << "\n"
    << k << "robust_kernel: " << ToString(o.robust_kernel) << "\n"
    << k << "robust_scale: " << o.robust_scale << "\n"
    << k << "translation_prior_sigma_m: " << Triple(o.translation_prior_sigma_m, 1.0) << "\n"
    << k << "rotation_prior_sigma_deg: " << Triple(o.rotation_prior_sigma_rad, kDegToRad) << "\n"
    << k << "pose_prior_sigma_trans_m: " << Triple(o.pose_prior_sigma_trans_m, 1.0) << "\n"
    << k << "pose_prior_sigma_rot_deg: " << Triple(o.pose_prior_sigma_rot_rad, kDegToRad) << "\n"
    << k << "max_extrinsic_change_deg: " << o.max_extrinsic_change_rad / kDegToRad << "\n"
    << k << "max_extrinsic_change_m: " << o.max_extrinsic_change_m << "\n"
    << k << "extrinsic_min_information_ratio: " << o.extrinsic_min_information_ratio << "\n"
    << k << "extrinsic_hold_unobserved: " << Bool(o.extrinsic_hold_unobserved) << "\n"
    << k << "extrinsic_prior_memory_markings: " << o.extrinsic_prior_memory_markings << "\n"
    << k << "extrinsic_holdout_every_n_frames: " << o.extrinsic_holdout_every_n_frames << "\n"
    << k << "extrinsic_holdout_sigmas: " << o.extrinsic_holdout_sigmas << "\n"
    << k << "max_lane_points_per_observation: " << o.max_lane_points_per_observation << "\n"
    << k << "max_lane_pixel_distance_m: " << o.max_lane_pixel_distance_m << "\n"
    << k << "lane_pixels_on_lane_surface: " << (o.lane_pixels_on_lane_surface ? "true" : "false")
    << "\n"
    << k << "max_outside_image_px: " << o.max_outside_image_px << "\n"
    << k << "max_measurements_per_marking: " << o.max_measurements_per_marking << "\n"
    << k << "road_height_sigma_m: " << o.road_height_sigma_m << "\n"
    << k << "road_height_sigma_per_m: " << o.road_height_sigma_per_m << "\n"
    << k << "road_crown_slope_sigma: " << o.road_crown_slope_sigma << "\n"
    << k << "road_crown_lateral_m: " << o.road_crown_lateral_m << "\n"
    << k << "road_plane_radius_m: " << o.road_plane_radius_m << "\n"
    << k << "lane_anchor_along_sigma_m: " << o.lane_anchor_along_sigma_m << "\n"
    << k << "lane_anchor_across_sigma_m: " << o.lane_anchor_across_sigma_m << "\n"
    << k << "lane_smoothness_sigma_m: " << o.lane_smoothness_sigma_m << "\n"
    << k << "map_step_pose_sigma_scale: " << o.map_step_pose_sigma_scale << "\n"
    << k << "motion_prior: " << Bool(o.motion_prior) << "\n"
    << k << "motion_sigma_acc_mps2: " << Triple(o.motion_sigma_acc_mps2, 1.0) << "\n"
    << k << "motion_sigma_angular_acc_radps2: " << Triple(o.motion_sigma_angular_acc_radps2, 1.0)
    << "\n"
    << k << "final_global_solve: " << Bool(o.final_global_solve) << "\n"
    << k << "final_global_max_frames: " << o.final_global_max_frames << "\n"
    << k << "final_global_rounds: " << o.final_global_rounds << "\n"
    << k
    << "final_global_min_measurements_per_marking: " << o.final_global_min_measurements_per_marking
    << "\n"
    << k << "final_global_joint_iterations: " << o.final_global_joint_iterations << "\n"
    << k << "final_global_from_mounting: " << Bool(o.final_global_from_mounting) << "\n";
  return s.str();
}

}  // namespace ipm_road_mapper
