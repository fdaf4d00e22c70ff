// Marking corner reprojection (paper, "Longitudinal Markings"):
//   r = (pi_k(M) - z_k) / sigma_px                                  (2 residuals, pixels/sigma)
// M: the corner in the map (3), z_k: its pixel measurement in frame k, pi_k the projection
// through the frame's pose T_map_base (q, t) and the extrinsic T_base_cam (q, t), see
// projection.h. One function computes it; three bindings choose which blocks are
// parameters: all five (CornerReprojectionResidual: corner_map[3], q_map_base[4],
// t_map_base[3], q_base_cam[4], t_base_cam[3]), the map + extrinsic step's (pose as data)
// and the pose step's (corner and extrinsic as data), so that autodiff carries only the
// derivatives a step needs.
#pragma once

#include <ceres/autodiff_cost_function.h>

#include <algorithm>

#include "ipm_road_mapper/core/residuals/projection.h"

namespace ipm_road_mapper {
namespace residuals {

// The residual, shared by the bindings below; false when the corner is behind the camera.
template <typename T>
bool CornerReprojection(const PinholeCamera& camera, const Eigen::Vector2d& uv_measured,
                        double inv_sigma, const T* const corner_map, const T* const q_map_base,
                        const T* const t_map_base, const T* const q_base_cam,
                        const T* const t_base_cam, T* residual) {
  Eigen::Matrix<T, 2, 1> uv;
  const Eigen::Matrix<T, 3, 1> p_map(corner_map[0], corner_map[1], corner_map[2]);
  if (!ProjectMapPoint(camera, q_map_base, t_map_base, q_base_cam, t_base_cam, p_map, &uv)) {
    return false;  // behind the camera: Ceres rejects the step
  }
  residual[0] = (uv(0) - T(uv_measured.x())) * T(inv_sigma);
  residual[1] = (uv(1) - T(uv_measured.y())) * T(inv_sigma);
  return true;
}

// All five blocks free (reference binding; tests, joint problems).
class CornerReprojectionResidual {
 public:
  CornerReprojectionResidual(const PinholeCamera& camera, const Eigen::Vector2d& uv_measured,
                             double sigma_px)
      : camera_(camera), uv_measured_(uv_measured), inv_sigma_(1.0 / sigma_px) {}

  template <typename T>
  bool operator()(const T* const corner_map, const T* const q_map_base,
                  const T* const t_map_base, const T* const q_base_cam,
                  const T* const t_base_cam, T* residual) const {
    return CornerReprojection(camera_, uv_measured_, inv_sigma_, corner_map, q_map_base,
                              t_map_base, q_base_cam, t_base_cam, residual);
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

// Map + extrinsic step: the frame's pose is data, so autodiff differentiates 10 parameters
// instead of 17. Parameter blocks: corner_map[3], q_base_cam[4], t_base_cam[3].
class CornerReprojectionMapStepResidual {
 public:
  CornerReprojectionMapStepResidual(const PinholeCamera& camera, const Eigen::Vector2d& uv,
                                    double sigma_px, const double* q_map_base,
                                    const double* t_map_base)
      : camera_(camera), uv_measured_(uv), inv_sigma_(1.0 / sigma_px) {
    std::copy(q_map_base, q_map_base + 4, q_map_base_);
    std::copy(t_map_base, t_map_base + 3, t_map_base_);
  }

  template <typename T>
  bool operator()(const T* const corner_map, const T* const q_base_cam,
                  const T* const t_base_cam, T* residual) const {
    const T q[4] = {T(q_map_base_[0]), T(q_map_base_[1]), T(q_map_base_[2]), T(q_map_base_[3])};
    const T t[3] = {T(t_map_base_[0]), T(t_map_base_[1]), T(t_map_base_[2])};
    return CornerReprojection(camera_, uv_measured_, inv_sigma_, corner_map, q, t, q_base_cam,
                              t_base_cam, residual);
  }

  static ceres::CostFunction* Create(const PinholeCamera& camera, const Eigen::Vector2d& uv,
                                     double sigma_px, const double* q_map_base,
                                     const double* t_map_base) {
    return new ceres::AutoDiffCostFunction<CornerReprojectionMapStepResidual, 2, 3, 4, 3>(
        new CornerReprojectionMapStepResidual(camera, uv, sigma_px, q_map_base, t_map_base));
  }

 private:
  PinholeCamera camera_;
  Eigen::Vector2d uv_measured_;
  double inv_sigma_;
  double q_map_base_[4], t_map_base_[3];
};

// Pose step: the corner and the extrinsic are data. Parameter blocks: q_map_base[4],
// t_map_base[3].
class CornerReprojectionPoseStepResidual {
 public:
  CornerReprojectionPoseStepResidual(const PinholeCamera& camera, const Eigen::Vector2d& uv,
                                     double sigma_px, const Eigen::Vector3d& corner_map,
                                     const double* q_base_cam, const double* t_base_cam)
      : camera_(camera), uv_measured_(uv), inv_sigma_(1.0 / sigma_px), corner_map_(corner_map) {
    std::copy(q_base_cam, q_base_cam + 4, q_base_cam_);
    std::copy(t_base_cam, t_base_cam + 3, t_base_cam_);
  }

  template <typename T>
  bool operator()(const T* const q_map_base, const T* const t_map_base, T* residual) const {
    const T corner[3] = {T(corner_map_(0)), T(corner_map_(1)), T(corner_map_(2))};
    const T q[4] = {T(q_base_cam_[0]), T(q_base_cam_[1]), T(q_base_cam_[2]), T(q_base_cam_[3])};
    const T t[3] = {T(t_base_cam_[0]), T(t_base_cam_[1]), T(t_base_cam_[2])};
    return CornerReprojection(camera_, uv_measured_, inv_sigma_, corner, q_map_base, t_map_base,
                              q, t, residual);
  }

  static ceres::CostFunction* Create(const PinholeCamera& camera, const Eigen::Vector2d& uv,
                                     double sigma_px, const Eigen::Vector3d& corner_map,
                                     const double* q_base_cam, const double* t_base_cam) {
    return new ceres::AutoDiffCostFunction<CornerReprojectionPoseStepResidual, 2, 4, 3>(
        new CornerReprojectionPoseStepResidual(camera, uv, sigma_px, corner_map, q_base_cam,
                                               t_base_cam));
  }

 private:
  PinholeCamera camera_;
  Eigen::Vector2d uv_measured_;
  double inv_sigma_;
  Eigen::Vector3d corner_map_;
  double q_base_cam_[4], t_base_cam_[3];
};

}  // namespace residuals
}  // namespace ipm_road_mapper
