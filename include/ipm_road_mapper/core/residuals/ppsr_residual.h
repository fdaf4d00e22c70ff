// Projected point-to-spline residual, PPSR (paper, "Lanes"). For a lane pixel z whose IPM
// point falls on the spline segment between control points c1 and c2:
//   a = pi_k(c1), b = pi_k(c2), d = (b - a) / |b - a|
//   r = (I - d d^T)(a - z) / sigma_px                                (2 residuals)
// i.e. the component of (a - z) orthogonal to the projected segment: the pixel's distance
// to the line through the projected control points. It uses only the pixel, never the
// pixel's own (biased) IPM point, so IPM error does not enter the estimate; the residual
// vector has rank 1 (it lies along the segment's normal), which Ceres handles fine.
// One function computes it; the bindings choose the parameters: all six blocks
// (PpsrResidual: c1[3], c2[3], q_map_base[4], t_map_base[3], q_base_cam[4], t_base_cam[3]),
// the map + extrinsic step's (pose as data) and the pose step's (map and extrinsic as data).
#pragma once

#include <ceres/autodiff_cost_function.h>

#include <algorithm>

#include "ipm_road_mapper/core/residuals/projection.h"

namespace ipm_road_mapper {
namespace residuals {

// Projected control points closer than this (px) give no usable direction.
constexpr double kPpsrMinSegmentPx = 1e-3;

// The residual, shared by the bindings below; false when a control point is behind the
// camera or the projected segment is degenerate.
template <typename T>
bool Ppsr(const PinholeCamera& camera, const Eigen::Vector2d& uv_measured, double inv_sigma,
          const T* const c1, const T* const c2, const T* const q_map_base,
          const T* const t_map_base, const T* const q_base_cam, const T* const t_base_cam,
          T* residual) {
  Eigen::Matrix<T, 2, 1> a, b;
  if (!ProjectMapPoint(camera, q_map_base, t_map_base, q_base_cam, t_base_cam,
                       Eigen::Matrix<T, 3, 1>(c1[0], c1[1], c1[2]), &a) ||
      !ProjectMapPoint(camera, q_map_base, t_map_base, q_base_cam, t_base_cam,
                       Eigen::Matrix<T, 3, 1>(c2[0], c2[1], c2[2]), &b)) {
    return false;
  }
  const Eigen::Matrix<T, 2, 1> ab = b - a;
  const T length = ab.norm();
  if (length < T(kPpsrMinSegmentPx)) return false;
  const Eigen::Matrix<T, 2, 1> d = ab / length;
  const Eigen::Matrix<T, 2, 1> e = a - uv_measured.cast<T>();
  const Eigen::Matrix<T, 2, 1> r = e - d * d.dot(e);
  residual[0] = r(0) * T(inv_sigma);
  residual[1] = r(1) * T(inv_sigma);
  return true;
}

// All six blocks free (reference binding).
class PpsrResidual {
 public:
  static constexpr double kMinSegmentPx = kPpsrMinSegmentPx;

  PpsrResidual(const PinholeCamera& camera, const Eigen::Vector2d& uv_measured, double sigma_px)
      : camera_(camera), uv_measured_(uv_measured), inv_sigma_(1.0 / sigma_px) {}

  template <typename T>
  bool operator()(const T* const c1, const T* const c2, const T* const q_map_base,
                  const T* const t_map_base, const T* const q_base_cam,
                  const T* const t_base_cam, T* residual) const {
    return Ppsr(camera_, uv_measured_, inv_sigma_, c1, c2, q_map_base, t_map_base, q_base_cam,
                t_base_cam, residual);
  }

  static ceres::CostFunction* Create(const PinholeCamera& camera, const Eigen::Vector2d& uv,
                                     double sigma_px) {
    return new ceres::AutoDiffCostFunction<PpsrResidual, 2, 3, 3, 4, 3, 4, 3>(
        new PpsrResidual(camera, uv, sigma_px));
  }

 private:
  PinholeCamera camera_;
  Eigen::Vector2d uv_measured_;
  double inv_sigma_;
};

// Map + extrinsic step: the frame's pose is data. Parameter blocks: c1[3], c2[3],
// q_base_cam[4], t_base_cam[3].
class PpsrMapStepResidual {
 public:
  PpsrMapStepResidual(const PinholeCamera& camera, const Eigen::Vector2d& uv, double sigma_px,
                      const double* q_map_base, const double* t_map_base)
      : camera_(camera), uv_measured_(uv), inv_sigma_(1.0 / sigma_px) {
    std::copy(q_map_base, q_map_base + 4, q_map_base_);
    std::copy(t_map_base, t_map_base + 3, t_map_base_);
  }

  template <typename T>
  bool operator()(const T* const c1, const T* const c2, const T* const q_base_cam,
                  const T* const t_base_cam, T* residual) const {
    const T q[4] = {T(q_map_base_[0]), T(q_map_base_[1]), T(q_map_base_[2]), T(q_map_base_[3])};
    const T t[3] = {T(t_map_base_[0]), T(t_map_base_[1]), T(t_map_base_[2])};
    return Ppsr(camera_, uv_measured_, inv_sigma_, c1, c2, q, t, q_base_cam, t_base_cam,
                residual);
  }

  static ceres::CostFunction* Create(const PinholeCamera& camera, const Eigen::Vector2d& uv,
                                     double sigma_px, const double* q_map_base,
                                     const double* t_map_base) {
    return new ceres::AutoDiffCostFunction<PpsrMapStepResidual, 2, 3, 3, 4, 3>(
        new PpsrMapStepResidual(camera, uv, sigma_px, q_map_base, t_map_base));
  }

 private:
  PinholeCamera camera_;
  Eigen::Vector2d uv_measured_;
  double inv_sigma_;
  double q_map_base_[4], t_map_base_[3];
};

// Pose step: control points and extrinsic are data. Parameter blocks: q_map_base[4],
// t_map_base[3].
class PpsrPoseStepResidual {
 public:
  PpsrPoseStepResidual(const PinholeCamera& camera, const Eigen::Vector2d& uv, double sigma_px,
                       const Eigen::Vector3d& c1, const Eigen::Vector3d& c2,
                       const double* q_base_cam, const double* t_base_cam)
      : camera_(camera), uv_measured_(uv), inv_sigma_(1.0 / sigma_px), c1_(c1), c2_(c2) {
    std::copy(q_base_cam, q_base_cam + 4, q_base_cam_);
    std::copy(t_base_cam, t_base_cam + 3, t_base_cam_);
  }

  template <typename T>
  bool operator()(const T* const q_map_base, const T* const t_map_base, T* residual) const {
    const T c1[3] = {T(c1_(0)), T(c1_(1)), T(c1_(2))};
    const T c2[3] = {T(c2_(0)), T(c2_(1)), T(c2_(2))};
    const T q[4] = {T(q_base_cam_[0]), T(q_base_cam_[1]), T(q_base_cam_[2]), T(q_base_cam_[3])};
    const T t[3] = {T(t_base_cam_[0]), T(t_base_cam_[1]), T(t_base_cam_[2])};
    return Ppsr(camera_, uv_measured_, inv_sigma_, c1, c2, q_map_base, t_map_base, q, t,
                residual);
  }

  static ceres::CostFunction* Create(const PinholeCamera& camera, const Eigen::Vector2d& uv,
                                     double sigma_px, const Eigen::Vector3d& c1,
                                     const Eigen::Vector3d& c2, const double* q_base_cam,
                                     const double* t_base_cam) {
    return new ceres::AutoDiffCostFunction<PpsrPoseStepResidual, 2, 4, 3>(
        new PpsrPoseStepResidual(camera, uv, sigma_px, c1, c2, q_base_cam, t_base_cam));
  }

 private:
  PinholeCamera camera_;
  Eigen::Vector2d uv_measured_;
  double inv_sigma_;
  Eigen::Vector3d c1_, c2_;
  double q_base_cam_[4], t_base_cam_[3];
};

}  // namespace residuals
}  // namespace ipm_road_mapper
