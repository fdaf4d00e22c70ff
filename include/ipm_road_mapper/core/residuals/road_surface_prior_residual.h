// Weak prior that a map point lies near the ground plane of the frame that saw it closest:
//   r = e_z^T R_base_map (p_map - t_map_base) / sigma_m                 (1 residual)
// Why: with free 3D map points and a nearly straight drive, a rotation of the camera about
// the direction of travel (extrinsic roll) is exactly compensated by rotating the whole map
// about the trajectory line, so roll is unobservable from reprojection alone. Near the
// vehicle the road is close to base_link's z = 0 plane (the IPM assumption, used here
// locally and softly), which pins that rotation. The pose is data (map step only).
// Parameter block: p_map[3].
#pragma once

#include <ceres/autodiff_cost_function.h>

#include <Eigen/Geometry>

namespace ipm_road_mapper {
namespace residuals {

class GroundHeightPriorResidual {
 public:
  GroundHeightPriorResidual(const Eigen::Isometry3d& T_map_base, double sigma_m)
      : row_(T_map_base.linear().col(2)),  // z row of R_base_map = z column of R_map_base
        offset_(row_.dot(T_map_base.translation())),
        inv_sigma_(1.0 / sigma_m) {}

  template <typename T>
  bool operator()(const T* const p_map, T* residual) const {
    const T z_base =
        T(row_(0)) * p_map[0] + T(row_(1)) * p_map[1] + T(row_(2)) * p_map[2] - T(offset_);
    residual[0] = z_base * T(inv_sigma_);
    return true;
  }

  static ceres::CostFunction* Create(const Eigen::Isometry3d& T_map_base, double sigma_m) {
    return new ceres::AutoDiffCostFunction<GroundHeightPriorResidual, 1, 3>(
        new GroundHeightPriorResidual(T_map_base, sigma_m));
  }

 private:
  Eigen::Vector3d row_;
  double offset_;
  double inv_sigma_;
};

}  // namespace residuals
}  // namespace ipm_road_mapper
