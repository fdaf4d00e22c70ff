// Weak anchor of a lane control point to where it was when the window was built:
//   r = (c - c_0) / sigma_m                                           (3 residuals)
// PPSR only measures a pixel's distance across the projected segment, so a control point
// may slide along its lane at no cost (a gauge freedom of each point). This prior removes
// that freedom; with sigma ~ 1 m it is negligible across the lane, where PPSR constrains it
// to centimeters. Parameter block: c[3].
#pragma once

#include <ceres/autodiff_cost_function.h>

#include <Eigen/Core>

namespace ipm_road_mapper {
namespace residuals {

class PointAnchorResidual {
 public:
  PointAnchorResidual(const Eigen::Vector3d& c0, double sigma_m) : c0_(c0), inv_sigma_(1.0 / sigma_m) {}

  template <typename T>
  bool operator()(const T* const c, T* residual) const {
    for (int i = 0; i < 3; ++i) residual[i] = (c[i] - T(c0_(i))) * T(inv_sigma_);
    return true;
  }

  static ceres::CostFunction* Create(const Eigen::Vector3d& c0, double sigma_m) {
    return new ceres::AutoDiffCostFunction<PointAnchorResidual, 3, 3>(
        new PointAnchorResidual(c0, sigma_m));
  }

 private:
  Eigen::Vector3d c0_;
  double inv_sigma_;
};

}  // namespace residuals
}  // namespace ipm_road_mapper
