#include "ipm_road_mapper/sim/vehicle.h"

#include <cmath>

#include "ipm_road_mapper/core/geometry/rigid_transform.h"
#include "ipm_road_mapper/sim/sim_random.h"

namespace ipm_road_mapper {
namespace sim {
namespace {

constexpr double kDegToRad = M_PI / 180.0;

}  // namespace

Eigen::Isometry3d MountToTransform(const CameraMount& mount) {
  // Mount frame (x forward, y left, z up) -> optical frame (z forward, x right, y down).
  Eigen::Matrix3d R_mount_optical;
  R_mount_optical << 0.0, 0.0, 1.0, -1.0, 0.0, 0.0, 0.0, -1.0, 0.0;
  Eigen::Isometry3d T_base_cam = Eigen::Isometry3d::Identity();
  T_base_cam.linear() = RotationFromRpy(mount.roll_deg * kDegToRad, mount.pitch_deg * kDegToRad,
                                        mount.yaw_deg * kDegToRad) *
                        R_mount_optical;
  T_base_cam.translation() = Eigen::Vector3d(mount.x_m, mount.y_m, mount.z_m);
  return T_base_cam;
}

Eigen::Isometry3d RoughExtrinsic(const CameraMount& true_mount,
                                 const RoughExtrinsicOptions& rough) {
  CameraMount m = true_mount;
  m.roll_deg += rough.roll_deg;
  m.pitch_deg += rough.pitch_deg;
  m.yaw_deg += rough.yaw_deg;
  m.x_m += rough.x_m;
  m.y_m += rough.y_m;
  m.z_m += rough.z_m;
  return MountToTransform(m);
}

VehicleTrajectory::VehicleTrajectory(const RoadModel& road, const VehicleOptions& options,
                                     std::uint64_t seed)
    : road_(road), options_(options), lane_offset_(road.LaneCenterOffset(options.lane)) {
  SimRandom random = SimRandom::ForStream(seed, RandomStream::kBodyMotion);
  phase_pitch_ = random.Uniform(0.0, 2.0 * M_PI);
  phase_roll_ = random.Uniform(0.0, 2.0 * M_PI);
  phase_heave_ = random.Uniform(0.0, 2.0 * M_PI);
  phase_wander_ = random.Uniform(0.0, 2.0 * M_PI);
}

double VehicleTrajectory::L(double t) const {
  return lane_offset_ + options_.wander_amplitude_m *
                            std::sin(2.0 * M_PI * t / options_.wander_period_s + phase_wander_);
}

Eigen::Isometry3d VehicleTrajectory::Pose(double t) const {
  const double s = S(t), l = L(t);
  const CenterlinePoint c = road_.Centerline(s);
  // Direction of motion: along the road plus the wander's lateral rate.
  const double dl_dt = options_.wander_amplitude_m * 2.0 * M_PI / options_.wander_period_s *
                       std::cos(2.0 * M_PI * t / options_.wander_period_s + phase_wander_);
  const double yaw = c.heading + std::atan2(dl_dt, options_.speed_mps * (1.0 - c.curvature * l));
  // The body rests on the surface: pitch from the axles, roll from the wheels (REP-103:
  // nose up is negative pitch, left side up is positive roll).
  const double half_wb = 0.5 * options_.wheelbase_m, half_track = 0.5 * options_.track_m;
  const double road_pitch = -std::atan(
      (road_.Height(s + half_wb, l) - road_.Height(s - half_wb, l)) / options_.wheelbase_m);
  const double road_roll = std::atan(
      (road_.Height(s, l + half_track) - road_.Height(s, l - half_track)) / options_.track_m);
  const double body_pitch = options_.pitch_amplitude_deg * kDegToRad *
                            std::sin(2.0 * M_PI * options_.pitch_frequency_hz * t + phase_pitch_);
  const double body_roll = options_.roll_amplitude_deg * kDegToRad *
                           std::sin(2.0 * M_PI * options_.roll_frequency_hz * t + phase_roll_);
  const double heave = options_.heave_amplitude_m *
                       std::sin(2.0 * M_PI * options_.heave_frequency_hz * t + phase_heave_);
  Eigen::Isometry3d T_map_base = Eigen::Isometry3d::Identity();
  T_map_base.linear() = RotationFromRpy(road_roll + body_roll, road_pitch + body_pitch, yaw);
  T_map_base.translation() = road_.SurfacePoint(s, l) + heave * T_map_base.linear().col(2);
  return T_map_base;
}

OdometryErrorModel::OdometryErrorModel(const OdometryOptions& options, std::uint64_t seed)
    : options_(options),
      seed_(seed),
      sigma_(options.xy_std_m, options.xy_std_m, options.yaw_std_deg * kDegToRad) {}

Eigen::Vector3d OdometryErrorModel::Next(double dt) {
  SimRandom random = SimRandom::ForStream(seed_, RandomStream::kOdometry, count_);
  if (count_ == 0) {
    for (int i = 0; i < 3; ++i) state_(i) = sigma_(i) * random.Normal();
  } else {
    const double a = std::exp(-dt / options_.correlation_time_s);
    const double b = std::sqrt(std::max(0.0, 1.0 - a * a));
    for (int i = 0; i < 3; ++i) state_(i) = a * state_(i) + sigma_(i) * b * random.Normal();
  }
  ++count_;
  const Eigen::Vector3d jitter(options_.jitter_xy_m * random.Normal(),
                               options_.jitter_xy_m * random.Normal(),
                               options_.jitter_yaw_deg * kDegToRad * random.Normal());
  return state_ + jitter;
}

Eigen::Isometry3d OdometryErrorModel::Apply(const Eigen::Isometry3d& T_map_base_true,
                                            const Eigen::Vector3d& error) {
  Eigen::Isometry3d T = T_map_base_true;
  T.linear() = Eigen::AngleAxisd(error.z(), Eigen::Vector3d::UnitZ()).toRotationMatrix() *
               T_map_base_true.linear();
  T.translation() += Eigen::Vector3d(error.x(), error.y(), 0.0);
  return T;
}

}  // namespace sim
}  // namespace ipm_road_mapper
