// The pixel covariance a measurement has in the map + extrinsic step, where the frame's pose
// is data although it is uncertain: the segmentation's sigma plus the pose's uncertainty
// carried into the image,
//   S = sigma_px^2 I + J Sigma_pose J^T,   J = d uv / d (rotation, translation of base_link)
// with the pose perturbed on the right, T' = T Exp(dtheta, dt) in base_link axes, so that
//   p_base' = p_base - dtheta x p_base - dt  ->  d p_base = [p_base]x dtheta - dt,
//   d p_cam = R_cam_base d p_base,  d uv = (d uv / d p_cam) d p_cam.
// Without it a step that treats odometry poses (0.1 m, 0.1 deg of random error: 10 px at
// 10 m) as exact takes their errors for information: the extrinsic and the markings bend
// to fit them and the marginalized prior becomes confidently wrong. The whitening
// W = S^-1/2 (W^T W = S^-1) goes into the map-step residuals.
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

#include "ipm_road_mapper/core/backend/residuals/projection_jacobians.h"

namespace ipm_road_mapper {
namespace residuals {

// W for a point p_map seen from T_map_base with the given per-axis pose sigmas (base_link:
// translation x y z in m, rotation roll pitch yaw in rad). I / sigma_px when the point does
// not project.
inline Eigen::Matrix2d PoseUncertaintyWhitening(const PinholeCamera& camera,
                                                const Eigen::Isometry3d& T_map_base,
                                                const Eigen::Isometry3d& T_base_cam,
                                                const Eigen::Vector3d& p_map, double sigma_px,
                                                const Eigen::Vector3d& sigma_trans_m,
                                                const Eigen::Vector3d& sigma_rot_rad) {
  const Eigen::Vector3d p_base = T_map_base.inverse() * p_map;
  const Eigen::Matrix3d R_cam_base = T_base_cam.linear().transpose();
  Eigen::Vector2d uv;
  Eigen::Matrix<double, 2, 3> J_uv;
  Eigen::Matrix2d S = sigma_px * sigma_px * Eigen::Matrix2d::Identity();
  if (ProjectWithJacobian(camera, R_cam_base * (p_base - T_base_cam.translation()), &uv, &J_uv)) {
    Eigen::Matrix3d p_hat;
    p_hat << 0.0, -p_base.z(), p_base.y(), p_base.z(), 0.0, -p_base.x(), -p_base.y(), p_base.x(),
        0.0;
    Eigen::Matrix<double, 2, 6> J;
    J.leftCols<3>() = J_uv * R_cam_base * p_hat;
    J.rightCols<3>() = -J_uv * R_cam_base;
    Eigen::Matrix<double, 6, 1> variances;
    variances << sigma_rot_rad.cwiseAbs2(), sigma_trans_m.cwiseAbs2();
    S += J * variances.asDiagonal() * J.transpose();
  }
  // S = L L^T -> W = L^-1 (then W^T W = S^-1).
  const Eigen::Matrix2d L = S.llt().matrixL();
  return L.inverse();
}

}  // namespace residuals
}  // namespace ipm_road_mapper
