// Marking edge reprojection: a measured side of a partially seen marking (docs/backend.md,
// "Partial views"). A side whose own boundary was seen, but one of whose corners was cut by
// the image border, an occluder or the range, still measures where the side's line is. For
// an observed pixel z on that boundary and the side's corners c1, c2 in the map:
//   p_i = R_cam_base (R_base_map (c_i - t_map_base) - t_base_cam)       (camera frame)
//   l   = p_1 x p_2                         (normal of the plane through the camera center
//                                            and the 3D side: the side's image line in
//                                            normalized coordinates, l . x = 0)
//   x   = (x_n, y_n, 1)                     (z undistorted to normalized coordinates)
//   r   = (l . x) / sqrt((l_0 / f_x)^2 + (l_1 / f_y)^2) / sigma_px             (1 residual)
// Derivation: with K the pinhole matrix, the line in pixels is l_px = K^-T l and a pixel
// z_px = K x, so l_px . z_px = l . x and the pixel distance of z_px from the line is
// (l . x) / |(l_px_0, l_px_1)| = (l . x) / |(l_0 / f_x, l_1 / f_y)|: the perpendicular pixel
// distance from the observed edge pixel to the projection of the map side (the line through
// the two projected corners, the PPSR idea applied to a marking's side). Built from the
// cross product, it needs neither corner to be in the image nor in front of the camera (a
// crossing's far-off corners are out of view by construction); it fails only when the side
// passes through the camera center. The pixel's own IPM point never enters it.
// One function computes it; the bindings choose the parameters: all six blocks
// (EdgeReprojectionResidual: c1[3], c2[3], q_map_base[4], t_map_base[3], q_base_cam[4],
// t_base_cam[3]), the map + extrinsic step's (pose as data) and the pose step's (corners and
// extrinsic as data); autodiffed.
#pragma once

#include <ceres/autodiff_cost_function.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "ipm_road_mapper/core/geometry/pinhole_camera.h"

namespace ipm_road_mapper {
namespace residuals {

// Below this norm of the image line (normalized units, m^2 in the camera frame) the side
// passes (almost) through the camera center and has no image line.
constexpr double kEdgeMinLineNorm = 1e-12;

// The residual, shared by the bindings below. `x_normalized` is the observed pixel
// undistorted to normalized coordinates; false for a side through the camera center.
template <typename T>
bool EdgeReprojection(const CameraIntrinsics& in, const Eigen::Vector2d& x_normalized,
                      double inv_sigma, const T* const c1, const T* const c2,
                      const T* const q_map_base, const T* const t_map_base,
                      const T* const q_base_cam, const T* const t_base_cam, T* residual) {
  using std::sqrt;
  const Eigen::Map<const Eigen::Quaternion<T>> q_mb(q_map_base);
  const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t_mb(t_map_base);
  const Eigen::Map<const Eigen::Quaternion<T>> q_bc(q_base_cam);
  const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t_bc(t_base_cam);
  auto to_cam = [&](const T* const c) {
    const Eigen::Matrix<T, 3, 1> p_map(c[0], c[1], c[2]);
    return Eigen::Matrix<T, 3, 1>(q_bc.conjugate() * (q_mb.conjugate() * (p_map - t_mb) - t_bc));
  };
  const Eigen::Matrix<T, 3, 1> line = to_cam(c1).cross(to_cam(c2));
  const T scale_x = line(0) / T(in.fx), scale_y = line(1) / T(in.fy);
  const T norm2 = scale_x * scale_x + scale_y * scale_y;
  if (!(norm2 > T(kEdgeMinLineNorm))) return false;
  const T distance = line(0) * T(x_normalized.x()) + line(1) * T(x_normalized.y()) + line(2);
  residual[0] = distance / sqrt(norm2) * T(inv_sigma);
  return true;
}

// All six blocks free (reference binding; tests).
class EdgeReprojectionResidual {
 public:
  // `uv` is the observed (distorted) pixel.
  EdgeReprojectionResidual(const PinholeCamera& camera, const Eigen::Vector2d& uv, double sigma_px)
      : in_(camera.intrinsics()),
        x_normalized_(camera.UndistortToNormalized(uv)),
        inv_sigma_(1.0 / sigma_px) {}

  template <typename T>
  bool operator()(const T* const c1, const T* const c2, const T* const q_map_base,
                  const T* const t_map_base, const T* const q_base_cam, const T* const t_base_cam,
                  T* residual) const {
    return EdgeReprojection(in_, x_normalized_, inv_sigma_, c1, c2, q_map_base, t_map_base,
                            q_base_cam, t_base_cam, residual);
  }

  static ceres::CostFunction* Create(const PinholeCamera& camera, const Eigen::Vector2d& uv,
                                     double sigma_px) {
    return new ceres::AutoDiffCostFunction<EdgeReprojectionResidual, 1, 3, 3, 4, 3, 4, 3>(
        new EdgeReprojectionResidual(camera, uv, sigma_px));
  }

 private:
  CameraIntrinsics in_;
  Eigen::Vector2d x_normalized_;
  double inv_sigma_;
};

// Map + extrinsic step: the frame's pose is data. Parameter blocks: c1[3], c2[3],
// q_base_cam[4], t_base_cam[3].
class EdgeReprojectionMapStepResidual {
 public:
  EdgeReprojectionMapStepResidual(const PinholeCamera& camera, const Eigen::Vector2d& uv,
                                  double sigma_px, const double* q_map_base,
                                  const double* t_map_base)
      : reference_(camera, uv, sigma_px) {
    std::copy(q_map_base, q_map_base + 4, q_map_base_);
    std::copy(t_map_base, t_map_base + 3, t_map_base_);
  }

  template <typename T>
  bool operator()(const T* const c1, const T* const c2, const T* const q_base_cam,
                  const T* const t_base_cam, T* residual) const {
    T q[4], t[3];
    for (int i = 0; i < 4; ++i) q[i] = T(q_map_base_[i]);
    for (int i = 0; i < 3; ++i) t[i] = T(t_map_base_[i]);
    return reference_(c1, c2, q, t, q_base_cam, t_base_cam, residual);
  }

  static ceres::CostFunction* Create(const PinholeCamera& camera, const Eigen::Vector2d& uv,
                                     double sigma_px, const double* q_map_base,
                                     const double* t_map_base) {
    return new ceres::AutoDiffCostFunction<EdgeReprojectionMapStepResidual, 1, 3, 3, 4, 3>(
        new EdgeReprojectionMapStepResidual(camera, uv, sigma_px, q_map_base, t_map_base));
  }

 private:
  EdgeReprojectionResidual reference_;
  double q_map_base_[4];
  double t_map_base_[3];
};

// Pose step: the corners and the extrinsic are data. Parameter blocks: q_map_base[4],
// t_map_base[3].
class EdgeReprojectionPoseStepResidual {
 public:
  EdgeReprojectionPoseStepResidual(const PinholeCamera& camera, const Eigen::Vector2d& uv,
                                   double sigma_px, const Eigen::Vector3d& c1,
                                   const Eigen::Vector3d& c2, const double* q_base_cam,
                                   const double* t_base_cam)
      : reference_(camera, uv, sigma_px), c1_(c1), c2_(c2) {
    std::copy(q_base_cam, q_base_cam + 4, q_base_cam_);
    std::copy(t_base_cam, t_base_cam + 3, t_base_cam_);
  }

  template <typename T>
  bool operator()(const T* const q_map_base, const T* const t_map_base, T* residual) const {
    T c1[3], c2[3], q[4], t[3];
    for (int i = 0; i < 3; ++i) {
      c1[i] = T(c1_(i));
      c2[i] = T(c2_(i));
      t[i] = T(t_base_cam_[i]);
    }
    for (int i = 0; i < 4; ++i) q[i] = T(q_base_cam_[i]);
    return reference_(c1, c2, q_map_base, t_map_base, q, t, residual);
  }

  static ceres::CostFunction* Create(const PinholeCamera& camera, const Eigen::Vector2d& uv,
                                     double sigma_px, const Eigen::Vector3d& c1,
                                     const Eigen::Vector3d& c2, const double* q_base_cam,
                                     const double* t_base_cam) {
    return new ceres::AutoDiffCostFunction<EdgeReprojectionPoseStepResidual, 1, 4, 3>(
        new EdgeReprojectionPoseStepResidual(camera, uv, sigma_px, c1, c2, q_base_cam, t_base_cam));
  }

 private:
  EdgeReprojectionResidual reference_;
  Eigen::Vector3d c1_, c2_;
  double q_base_cam_[4];
  double t_base_cam_[3];
};

}  // namespace residuals
}  // namespace ipm_road_mapper
