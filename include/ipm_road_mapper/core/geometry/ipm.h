// Inverse perspective mapping (IPM): pixels <-> points on the ground plane z = 0 of
// base_link, from the camera intrinsics and the extrinsic T_base_cam.
//
// Ground point of a pixel: the ray from the camera center c = t_base_cam along
// d = R_base_cam * K^-1 * undistort(uv) meets z = 0 at p = c + lambda d, lambda = -c_z / d_z,
// which needs d_z < 0 (the ray points below the horizon).
//
// The homography H = K [r1 r2 -R_cam_base t_base_cam] (r1, r2 the first two columns of
// R_cam_base = R_base_cam^T) maps ground points (x, y, 1) to undistorted pixels; its
// inverse is the paper's IPM matrix, mapping undistorted pixels to the ground.
#pragma once

#include <Eigen/Geometry>

#include "ipm_road_mapper/core/geometry/pinhole_camera.h"
#include "ipm_road_mapper/core/geometry/scalar.h"

namespace ipm_road_mapper {

// Outcome of mapping one pixel to the ground.
enum class IpmStatus {
  kOk,
  kAboveHorizon,  // the pixel's ray does not descend to the ground (at or above horizon)
  kBeyondRange,   // the ground point is farther than max_range_m from base_link's origin
};

// Human-readable name of an IPM status (for logs and rejection counters).
const char* ToString(IpmStatus status);

// Maps pixels to the ground plane of base_link and ground points back to pixels.
class Ipm {
 public:
  // Rays must descend by at least this much (z of the unit ray, i.e. sin of the angle below
  // the horizon) to count as below the horizon.
  static constexpr double kMinRayDescent = 1e-6;

  Ipm(const PinholeCamera& camera, const Eigen::Isometry3d& T_base_cam, double max_range_m);

  const PinholeCamera& camera() const { return camera_; }
  const Eigen::Isometry3d& T_base_cam() const { return T_base_cam_; }
  double max_range_m() const { return max_range_m_; }

  // Pixel -> ground point in base_link (z = 0). *p_base is written only for kOk.
  IpmStatus PixelToGround(const Eigen::Vector2d& uv, Eigen::Vector3d* p_base) const;

  // Any point in base_link -> pixel (with distortion). False when behind the camera.
  bool BaseToPixel(const Eigen::Vector3d& p_base, Eigen::Vector2d* uv) const;

  // Ground (x, y, 1) -> undistorted pixel (u, v, 1), up to scale.
  Eigen::Matrix3d HomographyGroundToImage() const;

  // The paper's IPM matrix: undistorted pixel (u, v, 1) -> ground (x, y, 1), up to scale.
  Eigen::Matrix3d HomographyImageToGround() const { return HomographyGroundToImage().inverse(); }

  // The IPM function itself, templated for autodiff (IPM uncertainty Jacobians): ground
  // point of pixel uv for an extrinsic (R_base_cam, t_base_cam). Returns false when the
  // ray does not descend; no range check.
  template <typename T>
  static bool GroundPoint(const PinholeCamera& camera, const Eigen::Matrix<T, 3, 3>& R_base_cam,
                          const Eigen::Matrix<T, 3, 1>& t_base_cam,
                          const Eigen::Matrix<T, 2, 1>& uv, Eigen::Matrix<T, 3, 1>* p_base) {
    const Eigen::Matrix<T, 2, 1> xy = camera.UndistortToNormalized(uv);
    const Eigen::Matrix<T, 3, 1> ray_cam(xy(0), xy(1), T(1.0));
    const Eigen::Matrix<T, 3, 1> ray_base = R_base_cam * ray_cam;
    if (ScalarValue(ray_base(2)) > -kMinRayDescent * ScalarValue(ray_base.norm())) return false;
    const T lambda = -t_base_cam(2) / ray_base(2);
    *p_base = t_base_cam + lambda * ray_base;
    return true;
  }

 private:
  PinholeCamera camera_;
  Eigen::Isometry3d T_base_cam_;
  Eigen::Isometry3d T_cam_base_;
  double max_range_m_;
};

}  // namespace ipm_road_mapper
