// Projected point-to-spline residual, PPSR (paper, "Lanes"). For a lane pixel z whose IPM
// point falls on the spline segment between control points c1 and c2:
//   a = pi_k(c1), b = pi_k(c2), d = (b - a) / |b - a|
//   r = (I - d d^T)(a - z) / sigma_px                                (2 residuals)
// i.e. the component of (a - z) orthogonal to the projected segment: the pixel's distance
// to the line through the projected control points. It uses only the pixel, never the
// pixel's own (biased) IPM point, so IPM error does not enter the estimate; the residual
// vector has rank 1 (it lies along the segment's normal), which Ceres handles fine.
// Parameter blocks: c1[3], c2[3], q_map_base[4], t_map_base[3], q_base_cam[4], t_base_cam[3].
#pragma once

#include <ceres/autodiff_cost_function.h>

#include "ipm_road_mapper/core/residuals/projection.h"

namespace ipm_road_mapper {
namespace residuals {

class PpsrResidual {
 public:
  // Projected control points closer than this (px) give no usable direction.
  static constexpr double kMinSegmentPx = 1e-3;

  PpsrResidual(const PinholeCamera& camera, const Eigen::Vector2d& uv_measured, double sigma_px)
      : camera_(camera), uv_measured_(uv_measured), inv_sigma_(1.0 / sigma_px) {}

  template <typename T>
  bool operator()(const T* const c1, const T* const c2, const T* const q_map_base,
                  const T* const t_map_base, const T* const q_base_cam,
                  const T* const t_base_cam, T* residual) const {
    Eigen::Matrix<T, 2, 1> a, b;
    if (!ProjectMapPoint(camera_, q_map_base, t_map_base, q_base_cam, t_base_cam,
                         Eigen::Matrix<T, 3, 1>(c1[0], c1[1], c1[2]), &a) ||
        !ProjectMapPoint(camera_, q_map_base, t_map_base, q_base_cam, t_base_cam,
                         Eigen::Matrix<T, 3, 1>(c2[0], c2[1], c2[2]), &b)) {
      return false;
    }
    const Eigen::Matrix<T, 2, 1> ab = b - a;
    const T length = ab.norm();
    if (length < T(kMinSegmentPx)) return false;
    const Eigen::Matrix<T, 2, 1> d = ab / length;
    const Eigen::Matrix<T, 2, 1> e = a - uv_measured_.cast<T>();
    const Eigen::Matrix<T, 2, 1> r = e - d * d.dot(e);
    residual[0] = r(0) * T(inv_sigma_);
    residual[1] = r(1) * T(inv_sigma_);
    return true;
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

}  // namespace residuals
}  // namespace ipm_road_mapper
