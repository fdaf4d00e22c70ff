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
// the map + extrinsic step's (pose as data) and the pose step's (map and extrinsic as data);
// the step bindings with analytic Jacobians (projection_jacobians.h, PpsrWithJacobian).
#pragma once

#include <ceres/autodiff_cost_function.h>
#include <ceres/sized_cost_function.h>

#include <algorithm>

#include "ipm_road_mapper/core/backend/residuals/projection.h"
#include "ipm_road_mapper/core/backend/residuals/projection_jacobians.h"

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
                  const T* const t_map_base, const T* const q_base_cam, const T* const t_base_cam,
                  T* residual) const {
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

// d r / d a and d r / d b of r = (I - d d^T)(a - z), d = (b - a) / |b - a|:
//   dr = (I - d d^T) da - [(d.e) I + d e^T] dd,   dd = (I - d d^T)(db - da) / |b - a|
// with e = a - z. False when the projected segment is degenerate.
inline bool PpsrWithJacobian(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                             const Eigen::Vector2d& z, Eigen::Vector2d* r, Eigen::Matrix2d* dr_da,
                             Eigen::Matrix2d* dr_db) {
  const Eigen::Vector2d ab = b - a;
  const double length = ab.norm();
  if (length < kPpsrMinSegmentPx) return false;
  const Eigen::Vector2d d = ab / length;
  const Eigen::Vector2d e = a - z;
  const Eigen::Matrix2d across = Eigen::Matrix2d::Identity() - d * d.transpose();
  *r = across * e;
  const Eigen::Matrix2d M =
      (d.dot(e) * Eigen::Matrix2d::Identity() + d * e.transpose()) * across / length;
  *dr_da = across + M;
  *dr_db = -M;
  return true;
}

// Map + extrinsic step: the frame's pose is data; analytic Jacobians (checked against the
// autodiffed reference). Parameter blocks: c1[3], c2[3], q_base_cam[4], t_base_cam[3].
class PpsrMapStepResidual : public ceres::SizedCostFunction<2, 3, 3, 4, 3> {
 public:
  // `sqrt_information` whitens the residual: I / sigma_px, or the inverse square root of a
  // covariance that includes the frame's pose uncertainty (pose_uncertainty.h).
  PpsrMapStepResidual(const PinholeCamera& camera, const Eigen::Vector2d& uv,
                      const Eigen::Matrix2d& sqrt_information, const double* q_map_base,
                      const double* t_map_base)
      : camera_(camera),
        uv_measured_(uv),
        sqrt_information_(sqrt_information),
        R_base_map_(
            Eigen::Map<const Eigen::Quaterniond>(q_map_base).toRotationMatrix().transpose()),
        t_map_base_(Eigen::Map<const Eigen::Vector3d>(t_map_base)) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const Eigen::Matrix3d R_cam_base =
        Eigen::Map<const Eigen::Quaterniond>(parameters[2]).toRotationMatrix().transpose();
    const Eigen::Map<const Eigen::Vector3d> t_base_cam(parameters[3]);
    const Eigen::Vector3d v1 =
        R_base_map_ * (Eigen::Map<const Eigen::Vector3d>(parameters[0]) - t_map_base_) - t_base_cam;
    const Eigen::Vector3d v2 =
        R_base_map_ * (Eigen::Map<const Eigen::Vector3d>(parameters[1]) - t_map_base_) - t_base_cam;
    Eigen::Vector2d a, b, r;
    Eigen::Matrix<double, 2, 3> J_a, J_b;
    Eigen::Matrix2d dr_da, dr_db;
    if (!ProjectWithJacobian(camera_, R_cam_base * v1, &a, &J_a) ||
        !ProjectWithJacobian(camera_, R_cam_base * v2, &b, &J_b) ||
        !PpsrWithJacobian(a, b, uv_measured_, &r, &dr_da, &dr_db)) {
      return false;
    }
    StoreRowMajor(sqrt_information_ * r, residuals);
    if (!jacobians) return true;
    const Eigen::Matrix<double, 2, 3> J1 = sqrt_information_ * dr_da * J_a;  // d r / d p_cam1
    const Eigen::Matrix<double, 2, 3> J2 = sqrt_information_ * dr_db * J_b;  // d r / d p_cam2
    if (jacobians[0]) StoreRowMajor(J1 * R_cam_base * R_base_map_, jacobians[0]);
    if (jacobians[1]) StoreRowMajor(J2 * R_cam_base * R_base_map_, jacobians[1]);
    if (jacobians[2]) {
      StoreRowMajor(J1 * InverseRotationJacobian(parameters[2], v1) +
                        J2 * InverseRotationJacobian(parameters[2], v2),
                    jacobians[2]);
    }
    if (jacobians[3]) StoreRowMajor(-(J1 + J2) * R_cam_base, jacobians[3]);
    return true;
  }

  static ceres::CostFunction* Create(const PinholeCamera& camera, const Eigen::Vector2d& uv,
                                     double sigma_px, const double* q_map_base,
                                     const double* t_map_base) {
    return new PpsrMapStepResidual(camera, uv, Eigen::Matrix2d::Identity() / sigma_px, q_map_base,
                                   t_map_base);
  }
  static ceres::CostFunction* Create(const PinholeCamera& camera, const Eigen::Vector2d& uv,
                                     const Eigen::Matrix2d& sqrt_information,
                                     const double* q_map_base, const double* t_map_base) {
    return new PpsrMapStepResidual(camera, uv, sqrt_information, q_map_base, t_map_base);
  }

 private:
  PinholeCamera camera_;
  Eigen::Vector2d uv_measured_;
  Eigen::Matrix2d sqrt_information_;
  Eigen::Matrix3d R_base_map_;
  Eigen::Vector3d t_map_base_;
};

// Pose step: control points and extrinsic are data; analytic Jacobians. Parameter blocks:
// q_map_base[4], t_map_base[3].
class PpsrPoseStepResidual : public ceres::SizedCostFunction<2, 4, 3> {
 public:
  PpsrPoseStepResidual(const PinholeCamera& camera, const Eigen::Vector2d& uv, double sigma_px,
                       const Eigen::Vector3d& c1, const Eigen::Vector3d& c2,
                       const double* q_base_cam, const double* t_base_cam)
      : camera_(camera),
        uv_measured_(uv),
        inv_sigma_(1.0 / sigma_px),
        c1_(c1),
        c2_(c2),
        R_cam_base_(
            Eigen::Map<const Eigen::Quaterniond>(q_base_cam).toRotationMatrix().transpose()),
        t_base_cam_(Eigen::Map<const Eigen::Vector3d>(t_base_cam)) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const Eigen::Matrix3d R_map_base =
        Eigen::Map<const Eigen::Quaterniond>(parameters[0]).toRotationMatrix();
    const Eigen::Map<const Eigen::Vector3d> t_map_base(parameters[1]);
    const Eigen::Vector3d w1 = c1_ - t_map_base, w2 = c2_ - t_map_base;
    Eigen::Vector2d a, b, r;
    Eigen::Matrix<double, 2, 3> J_a, J_b;
    Eigen::Matrix2d dr_da, dr_db;
    if (!ProjectWithJacobian(camera_, R_cam_base_ * (R_map_base.transpose() * w1 - t_base_cam_), &a,
                             &J_a) ||
        !ProjectWithJacobian(camera_, R_cam_base_ * (R_map_base.transpose() * w2 - t_base_cam_), &b,
                             &J_b) ||
        !PpsrWithJacobian(a, b, uv_measured_, &r, &dr_da, &dr_db)) {
      return false;
    }
    StoreRowMajor(r * inv_sigma_, residuals);
    if (!jacobians) return true;
    const Eigen::Matrix<double, 2, 3> J1 =
        inv_sigma_ * dr_da * J_a * R_cam_base_;  // d r / d p_base1
    const Eigen::Matrix<double, 2, 3> J2 = inv_sigma_ * dr_db * J_b * R_cam_base_;
    if (jacobians[0]) {
      StoreRowMajor(J1 * InverseRotationJacobian(parameters[0], w1) +
                        J2 * InverseRotationJacobian(parameters[0], w2),
                    jacobians[0]);
    }
    if (jacobians[1]) {
      StoreRowMajor(-(J1 + J2) * R_map_base.transpose(), jacobians[1]);
    }
    return true;
  }

  static ceres::CostFunction* Create(const PinholeCamera& camera, const Eigen::Vector2d& uv,
                                     double sigma_px, const Eigen::Vector3d& c1,
                                     const Eigen::Vector3d& c2, const double* q_base_cam,
                                     const double* t_base_cam) {
    return new PpsrPoseStepResidual(camera, uv, sigma_px, c1, c2, q_base_cam, t_base_cam);
  }

 private:
  PinholeCamera camera_;
  Eigen::Vector2d uv_measured_;
  double inv_sigma_;
  Eigen::Vector3d c1_, c2_;
  Eigen::Matrix3d R_cam_base_;
  Eigen::Vector3d t_base_cam_;
};

}  // namespace residuals
}  // namespace ipm_road_mapper
