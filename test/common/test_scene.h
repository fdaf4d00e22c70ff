// Test helpers shared by the gtests: camera intrinsics, the camera mount T_base_cam and
// planar vehicle poses T_map_base. Tests whose values differ on purpose pass them as
// parameters; the defaults are the values most tests use.
#pragma once

#include <Eigen/Geometry>
#include <array>

#include "ipm_road_mapper/core/geometry/pinhole_camera.h"
#include "ipm_road_mapper/core/geometry/rigid_transform.h"

namespace ipm_road_mapper {
namespace test {

// Plumb_bob coefficients (k1, k2, p1, p2, k3) of a mildly distorted lens.
constexpr std::array<double, 5> kMildDistortion{{-0.05, 0.01, 0.0, 0.0, 0.0}};
// Plumb_bob coefficients of a strongly distorted lens (all five terms non-zero).
constexpr std::array<double, 5> kStrongDistortion{{-0.3, 0.1, 1e-3, -5e-4, -0.02}};

// A width x height pinhole camera with fx = fy = focal_px and principal point (cx, cy).
inline CameraIntrinsics Intrinsics(int width, int height, double focal_px, double cx, double cy,
                                   const std::array<double, 5>& distortion = {}) {
  CameraIntrinsics in;
  in.width = width;
  in.height = height;
  in.fx = in.fy = focal_px;
  in.cx = cx;
  in.cy = cy;
  in.distortion = distortion;
  return in;
}

// The 1280x720 test camera, fx = fy = 1000, by default centered and undistorted.
inline CameraIntrinsics Intrinsics1280x720(double cx = 640.0, double cy = 360.0,
                                           const std::array<double, 5>& distortion = {}) {
  return Intrinsics(1280, 720, 1000.0, cx, cy, distortion);
}

// 1280x720 with fx != fy and the principal point off-centre, so that swapping any two of
// them cannot go unnoticed; `distorted`: kStrongDistortion.
inline CameraIntrinsics AsymmetricIntrinsics(bool distorted) {
  CameraIntrinsics in = Intrinsics(1280, 720, 1000.0, 652.3, 351.7);
  in.fy = 1012.5;
  if (distorted) in.distortion = kStrongDistortion;
  return in;
}

// R_base_optical: the optical frame's axes in base_link (optical z -> base x, optical
// x -> -base y, optical y -> -base z), a camera looking straight ahead.
inline Eigen::Matrix3d BaseOpticalAxes() {
  Eigen::Matrix3d R_base_optical;
  R_base_optical << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  return R_base_optical;
}

// T_base_cam of a camera at t_base_cam_m that looks ahead, turned by roll, pitch (positive:
// nose down) and yaw (rad) about base_link's axes: RotationFromRpy(roll, pitch, yaw) *
// BaseOpticalAxes().
inline Eigen::Isometry3d MountedCamera(double roll_rad, double pitch_rad, double yaw_rad,
                                       const Eigen::Vector3d& t_base_cam_m = {1.5, 0.0, 1.5}) {
  Eigen::Isometry3d T_base_cam = Eigen::Isometry3d::Identity();
  T_base_cam.linear() = RotationFromRpy(roll_rad, pitch_rad, yaw_rad) * BaseOpticalAxes();
  T_base_cam.translation() = t_base_cam_m;
  return T_base_cam;
}

// A vehicle pose T_map_base on the z = 0 plane: at (x, y), heading yaw (rad).
inline Eigen::Isometry3d PlanarPose(double x_m, double y_m, double yaw_rad) {
  Eigen::Isometry3d T_map_base = Eigen::Isometry3d::Identity();
  T_map_base.linear() = RotationFromRpy(0.0, 0.0, yaw_rad);
  T_map_base.translation() = Eigen::Vector3d(x_m, y_m, 0.0);
  return T_map_base;
}

}  // namespace test
}  // namespace ipm_road_mapper
