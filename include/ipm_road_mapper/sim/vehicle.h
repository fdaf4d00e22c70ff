// Vehicle motion and odometry of a synthetic drive: the true base_link pose over time, the
// camera mount transforms, and the odometry error model.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>

#include "ipm_road_mapper/sim/road.h"
#include "ipm_road_mapper/sim/scenario.h"

namespace ipm_road_mapper {
namespace sim {

// T_base_cam of a camera mount (the optical frame: z forward, x right, y down).
Eigen::Isometry3d MountToTransform(const CameraMount& mount);

// The rough extrinsic handed to the mapper: the true mount with the offsets added to its
// angles and position.
Eigen::Isometry3d RoughExtrinsic(const CameraMount& true_mount, const RoughExtrinsicOptions& rough);

// The true trajectory. base_link's origin is the road surface point under the vehicle
// reference point (lane center plus a slow lateral wander), lifted by the body heave along
// the body z axis; yaw follows the direction of motion, pitch and roll follow the surface
// slope between the axles and between the wheels, plus the body's pitch and roll
// oscillations. Time t is in seconds since the first camera frame.
class VehicleTrajectory {
 public:
  VehicleTrajectory(const RoadModel& road, const VehicleOptions& options, std::uint64_t seed);

  // Arc length of the vehicle reference point along the centerline at time t.
  double S(double t) const { return options_.start_s_m + options_.speed_mps * t; }

  // Lateral offset of the reference point at time t.
  double L(double t) const;

  // True T_map_base at time t.
  Eigen::Isometry3d Pose(double t) const;

 private:
  const RoadModel& road_;
  VehicleOptions options_;
  double lane_offset_ = 0.0;
  double phase_pitch_ = 0.0, phase_roll_ = 0.0, phase_heave_ = 0.0, phase_wander_ = 0.0;
};

// Odometry error: independent Ornstein-Uhlenbeck processes on x, y (m, map frame) and yaw
// (rad), each with stationary standard deviation sigma and correlation time tau, sampled
// exactly: e_k+1 = a e_k + sigma sqrt(1 - a^2) n_k with a = exp(-dt / tau), started from the
// stationary distribution; plus white jitter per sample.
class OdometryErrorModel {
 public:
  OdometryErrorModel(const OdometryOptions& options, std::uint64_t seed);

  // The error (dx, dy, dyaw) of the next sample, `dt` seconds after the previous one
  // (the first call ignores dt).
  Eigen::Vector3d Next(double dt);

  // The odometry pose: yaw error rotates about base_link's origin (about the map z axis),
  // the x, y error shifts it in the map frame. Height, pitch and roll stay true.
  static Eigen::Isometry3d Apply(const Eigen::Isometry3d& T_map_base_true,
                                 const Eigen::Vector3d& error);

 private:
  OdometryOptions options_;
  std::uint64_t seed_;
  std::uint64_t count_ = 0;
  Eigen::Vector3d state_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d sigma_ = Eigen::Vector3d::Zero();
};

}  // namespace sim
}  // namespace ipm_road_mapper
