// Marking corner reprojection (paper, "Longitudinal Markings"):
//   r = (pi_k(M) - z_k) / sigma_px                                  (2 residuals, pixels/sigma)
// M: the corner in the map (3), z_k: its pixel measurement in frame k, pi_k the projection
// through the frame's pose T_map_base (q, t) and the extrinsic T_base_cam (q, t), see
// projection.h. One function computes it; three bindings choose which blocks are
// parameters: all five (CornerReprojectionResidual: corner_map[3], q_map_base[4],
// t_map_base[3], q_base_cam[4], t_base_cam[3]), the map + extrinsic step's (pose as data)
// and the pose step's (corner and extrinsic as data), so that autodiff carries only the
// derivatives a step needs (the step bindings analytically, projection_jacobians.h).
#pragma once

#include <ceres/autodiff_cost_function.h>
#include <ceres/sized_cost_function.h>

#include <algorithm>

#include "ipm_road_mapper/core/backend/residuals/projection.h"
#include "ipm_road_mapper/core/backend/residuals/projection_jacobians.h"

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
  bool operator()(const T* const corner_map, const T* const q_map_base, const T* const t_map_base,
                  const T* const q_base_cam, const T* const t_base_cam, T* residual) const {
    return CornerReprojection(camera_, uv_measured_, inv_sigma_, corner_map, q_map_base, t_map_base,
                              q_base_cam, t_base_cam, residual);
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

// Map + extrinsic step: the frame's pose is data. Analytic Jacobians (projection_jacobians.h),
// checked against the autodiffed reference binding. Parameter blocks: corner_map[3],
// q_base_cam[4], t_base_cam[3].
class CornerReprojectionMapStepResidual : public ceres::SizedCostFunction<2, 3, 4, 3> {
 public:
  // `sqrt_information` whitens the pixel error: I / sigma_px, or the inverse square root of
  // a covariance that includes the frame's pose uncertainty (pose_uncertainty.h).
  CornerReprojectionMapStepResidual(const PinholeCamera& camera, const Eigen::Vector2d& uv,
                                    const Eigen::Matrix2d& sqrt_information,
                                    const double* q_map_base, const double* t_map_base)
      : camera_(camera),
        uv_measured_(uv),
        sqrt_information_(sqrt_information),
        R_base_map_(
            Eigen::Map<const Eigen::Quaterniond>(q_map_base).toRotationMatrix().transpose()),
        t_map_base_(Eigen::Map<const Eigen::Vector3d>(t_map_base)) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const Eigen::Map<const Eigen::Vector3d> corner(parameters[0]);
    const Eigen::Matrix3d R_base_cam =
        Eigen::Map<const Eigen::Quaterniond>(parameters[1]).toRotationMatrix();
    const Eigen::Map<const Eigen::Vector3d> t_base_cam(parameters[2]);
    const Eigen::Vector3d v = R_base_map_ * (corner - t_map_base_) - t_base_cam;
    const Eigen::Matrix3d R_cam_base = R_base_cam.transpose();
    Eigen::Vector2d uv;
    Eigen::Matrix<double, 2, 3> J_uv;
    if (!ProjectWithJacobian(camera_, R_cam_base * v, &uv, jacobians ? &J_uv : nullptr)) {
      return false;
    }
    StoreRowMajor(sqrt_information_ * (uv - uv_measured_), residuals);
    if (!jacobians) return true;
    const Eigen::Matrix<double, 2, 3> J_cam = sqrt_information_ * J_uv;
    if (jacobians[0]) StoreRowMajor(J_cam * R_cam_base * R_base_map_, jacobians[0]);
    if (jacobians[1]) {
      StoreRowMajor(J_cam * InverseRotationJacobian(parameters[1], v), jacobians[1]);
    }
    if (jacobians[2]) StoreRowMajor(-J_cam * R_cam_base, jacobians[2]);
    return true;
  }

  static ceres::CostFunction* Create(const PinholeCamera& camera, const Eigen::Vector2d& uv,
                                     double sigma_px, const double* q_map_base,
                                     const double* t_map_base) {
    return new CornerReprojectionMapStepResidual(camera, uv, Eigen::Matrix2d::Identity() / sigma_px,
                                                 q_map_base, t_map_base);
  }
  static ceres::CostFunction* Create(const PinholeCamera& camera, const Eigen::Vector2d& uv,
                                     const Eigen::Matrix2d& sqrt_information,
                                     const double* q_map_base, const double* t_map_base) {
    return new CornerReprojectionMapStepResidual(camera, uv, sqrt_information, q_map_base,
                                                 t_map_base);
  }

 private:
  PinholeCamera camera_;
  Eigen::Vector2d uv_measured_;
  Eigen::Matrix2d sqrt_information_;
  Eigen::Matrix3d R_base_map_;
  Eigen::Vector3d t_map_base_;
};

// Pose step: the corner and the extrinsic are data; analytic Jacobians. Parameter blocks:
// q_map_base[4], t_map_base[3].
class CornerReprojectionPoseStepResidual : public ceres::SizedCostFunction<2, 4, 3> {
 public:
  CornerReprojectionPoseStepResidual(const PinholeCamera& camera, const Eigen::Vector2d& uv,
                                     double sigma_px, const Eigen::Vector3d& corner_map,
                                     const double* q_base_cam, const double* t_base_cam)
      : camera_(camera),
        uv_measured_(uv),
        inv_sigma_(1.0 / sigma_px),
        corner_map_(corner_map),
        R_cam_base_(
            Eigen::Map<const Eigen::Quaterniond>(q_base_cam).toRotationMatrix().transpose()),
        t_base_cam_(Eigen::Map<const Eigen::Vector3d>(t_base_cam)) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const Eigen::Matrix3d R_map_base =
        Eigen::Map<const Eigen::Quaterniond>(parameters[0]).toRotationMatrix();
    const Eigen::Map<const Eigen::Vector3d> t_map_base(parameters[1]);
    const Eigen::Vector3d v = corner_map_ - t_map_base;
    Eigen::Vector2d uv;
    Eigen::Matrix<double, 2, 3> J_uv;
    if (!ProjectWithJacobian(camera_, R_cam_base_ * (R_map_base.transpose() * v - t_base_cam_), &uv,
                             jacobians ? &J_uv : nullptr)) {
      return false;
    }
    StoreRowMajor((uv - uv_measured_) * inv_sigma_, residuals);
    if (!jacobians) return true;
    const Eigen::Matrix<double, 2, 3> J_base = inv_sigma_ * J_uv * R_cam_base_;
    if (jacobians[0]) {
      StoreRowMajor(J_base * InverseRotationJacobian(parameters[0], v), jacobians[0]);
    }
    if (jacobians[1]) {
      StoreRowMajor(-J_base * R_map_base.transpose(), jacobians[1]);
    }
    return true;
  }

  static ceres::CostFunction* Create(const PinholeCamera& camera, const Eigen::Vector2d& uv,
                                     double sigma_px, const Eigen::Vector3d& corner_map,
                                     const double* q_base_cam, const double* t_base_cam) {
    return new CornerReprojectionPoseStepResidual(camera, uv, sigma_px, corner_map, q_base_cam,
                                                  t_base_cam);
  }

 private:
  PinholeCamera camera_;
  Eigen::Vector2d uv_measured_;
  double inv_sigma_;
  Eigen::Vector3d corner_map_;
  Eigen::Matrix3d R_cam_base_;
  Eigen::Vector3d t_base_cam_;
};

}  // namespace residuals
}  // namespace ipm_road_mapper
