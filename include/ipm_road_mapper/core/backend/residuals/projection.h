// Shared by the reprojection residuals: a map point seen by the camera of frame k,
//   p_cam = R_cam_base (R_base_map (p_map - t_map_base) - t_base_cam),
//   uv    = pi(p_cam)                        (pinhole + plumb_bob, PinholeCamera::Project)
// with R_base_map = R_map_base^T and R_cam_base = R_base_cam^T. Rotations are Eigen
// quaternions stored (x, y, z, w), the layout of ceres::EigenQuaternionManifold.
#pragma once

#include <Eigen/Geometry>

#include "ipm_road_mapper/core/geometry/pinhole_camera.h"

namespace ipm_road_mapper {
namespace residuals {

// Projects p_map; false when the point is behind the camera.
template <typename T>
bool ProjectMapPoint(const PinholeCamera& camera, const T* const q_map_base,
                     const T* const t_map_base, const T* const q_base_cam,
                     const T* const t_base_cam, const Eigen::Matrix<T, 3, 1>& p_map,
                     Eigen::Matrix<T, 2, 1>* uv) {
  const Eigen::Map<const Eigen::Quaternion<T>> q_mb(q_map_base);
  const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t_mb(t_map_base);
  const Eigen::Map<const Eigen::Quaternion<T>> q_bc(q_base_cam);
  const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t_bc(t_base_cam);
  const Eigen::Matrix<T, 3, 1> p_base = q_mb.conjugate() * (p_map - t_mb);
  const Eigen::Matrix<T, 3, 1> p_cam = q_bc.conjugate() * (p_base - t_bc);
  return camera.Project(p_cam, uv);
}

}  // namespace residuals
}  // namespace ipm_road_mapper
