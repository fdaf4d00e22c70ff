// Inverse perspective mapping (IPM): pixels <-> points on a ground plane given in base_link,
// from the camera intrinsics and the extrinsic T_base_cam. The ground is the plane z = 0 of
// base_link unless a road plane is given (the front end's: the road under and ahead of the
// vehicle from its trajectory, trajectory_road_plane.h); ground points are always returned
// in base_link, on that plane.
//
// Ground point of a pixel: the ray from the camera center c = t_base_cam along
// d = R_base_cam * K^-1 * undistort(uv) meets the plane n . (p - p0) = 0 at p = c + lambda d,
// lambda = n . (p0 - c) / (n . d), which needs n . d < 0 (the ray points below the plane's
// horizon). For z = 0 (n = e_z, p0 = 0) that is lambda = -c_z / d_z.
//
// The homography H = K [r1 r2 -R_cam_base t_base_cam] (r1, r2 the first two columns of
// R_cam_base = R_base_cam^T) maps ground points (x, y, 1) to undistorted pixels; its
// inverse is the paper's IPM matrix, mapping undistorted pixels to the ground.
#pragma once

#include <Eigen/Geometry>

#include "ipm_road_mapper/core/geometry/pinhole_camera.h"
#include "ipm_road_mapper/core/geometry/road_surface.h"
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

// Maps pixels to the ground plane and ground points back to pixels.
class Ipm {
 public:
  // Rays must descend by at least this much (z of the unit ray, i.e. sin of the angle below
  // the horizon) to count as below the horizon.
  static constexpr double kMinRayDescent = 1e-6;

  // Ground = the plane z = 0 of base_link.
  Ipm(const PinholeCamera& camera, const Eigen::Isometry3d& T_base_cam, double max_range_m);

  // Ground = `ground_base`, a plane in base_link (its normal pointing up); the plane z = 0
  // (normal e_z through the origin) gives exactly the constructor above.
  Ipm(const PinholeCamera& camera, const Eigen::Isometry3d& T_base_cam, double max_range_m,
      const RoadPlane& ground_base);

  const PinholeCamera& camera() const { return camera_; }
  const Eigen::Isometry3d& T_base_cam() const { return T_base_cam_; }
  double max_range_m() const { return max_range_m_; }
  // The ground plane in base_link.
  const RoadPlane& ground_base() const { return ground_base_; }
  // True when the ground is base_link's z = 0.
  bool flat() const { return flat_; }

  // Pixel -> ground point in base_link (on the ground plane). *p_base is written only for
  // kOk. The range is the horizontal distance from base_link's origin.
  IpmStatus PixelToGround(const Eigen::Vector2d& uv, Eigen::Vector3d* p_base) const;

  // The ground point above or below (x, y) of base_link: (x, y, z) on the ground plane;
  // (x, y, 0) for the plane z = 0.
  Eigen::Vector3d OnGround(const Eigen::Vector2d& xy_base) const;

  // Any point in base_link -> pixel (with distortion). False when behind the camera.
  bool BaseToPixel(const Eigen::Vector3d& p_base, Eigen::Vector2d* uv) const;

  // Ground (x, y, 1) of base_link's plane z = 0 (whatever the ground) -> undistorted pixel
  // (u, v, 1), up to scale.
  Eigen::Matrix3d HomographyGroundToImage() const;

  // The paper's IPM matrix: undistorted pixel (u, v, 1) -> (x, y, 1) of base_link's z = 0.
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
  RoadPlane ground_base_;
  bool flat_ = true;
};

}  // namespace ipm_road_mapper
