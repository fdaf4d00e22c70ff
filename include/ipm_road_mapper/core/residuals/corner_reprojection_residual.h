// Marking corner reprojection (paper, "Longitudinal Markings"):
//   r = (pi_k(M) - z_k) / sigma_px                                  (2 residuals, pixels/sigma)
// M: the corner in the map (3), z_k: its pixel measurement in frame k, pi_k the projection
// through the frame's pose T_map_base (q, t) and the extrinsic T_base_cam (q, t), see
// projection.h. The same functor serves both steps: the map step holds the pose blocks
// constant, the pose step holds the corner and the extrinsic constant.
// Parameter blocks: corner_map[3], q_map_base[4], t_map_base[3], q_base_cam[4], t_base_cam[3].
#pragma once

#include <ceres/autodiff_cost_function.h>

#include "ipm_road_mapper/core/residuals/projection.h"

namespace ipm_road_mapper {
namespace residuals {

class CornerReprojectionResidual {
 public:
  CornerReprojectionResidual(const PinholeCamera& camera, const Eigen::Vector2d& uv_measured,
                             double sigma_px)
      : camera_(camera), uv_measured_(uv_measured), inv_sigma_(1.0 / sigma_px) {}

  template <typename T>
  bool operator()(const T* const corner_map, const T* const q_map_base,
                  const T* const t_map_base, const T* const q_base_cam,
                  const T* const t_base_cam, T* residual) const {
    Eigen::Matrix<T, 2, 1> uv;
    const Eigen::Matrix<T, 3, 1> p_map(corner_map[0], corner_map[1], corner_map[2]);
    if (!ProjectMapPoint(camera_, q_map_base, t_map_base, q_base_cam, t_base_cam, p_map, &uv)) {
      return false;  // behind the camera: Ceres rejects the step
    }
    residual[0] = (uv(0) - T(uv_measured_.x())) * T(inv_sigma_);
    residual[1] = (uv(1) - T(uv_measured_.y())) * T(inv_sigma_);
    return true;
  }

  static ceres::CostFunction* Create(const PinholeCamera& camera, const Eigen::Vector2d& uv,
                                     double sigma_px) {
    return new ceres::AutoDiffCostFunction<CornerReprojectionResidual, 2, 3, 4, 3, 4, 3>(
        new CornerReprojectionResidual(camera, uv, sigma_px));
  }

 private:
  PinholeCamera camera_;
  Eigen::Vector2d uv_measured_;
  double inv_sigma_;
};

}  // namespace residuals
}  // namespace ipm_road_mapper
