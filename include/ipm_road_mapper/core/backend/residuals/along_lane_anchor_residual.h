// Anchor of a lane control point where it was when the window was built, tight along its
// lane and loose across it:
//   r = [ t^T (c - c_0) / sigma_along ;  (I - t t^T)(c - c_0) / sigma_across ]   (4 residuals)
// with t the lane's unit tangent at c_0. PPSR measures a pixel's distance across the
// projected segment only, so a control point can slide along its lane at no cost (a gauge
// freedom of each point: the curve's shape does not depend on where along it a control
// point sits, only the parameterization does). Left free, the points of a window slide by
// meters and squeeze together, so that direction is held tightly. Across the lane the data
// decide; the loose term (sigma_across ~ 0.5 m, hundreds of times weaker than a few pixels
// of PPSR) only keeps a point that its pixels barely reach (one pixel next to its
// neighbor lets the segment swing about it) from flying off. Parameter block: c[3].
#pragma once

#include <ceres/autodiff_cost_function.h>

#include <Eigen/Core>

namespace ipm_road_mapper {
namespace residuals {

class AlongLaneAnchorResidual {
 public:
  // `tangent` need not be unit; a zero tangent leaves only the isotropic loose term.
  AlongLaneAnchorResidual(const Eigen::Vector3d& c0, const Eigen::Vector3d& tangent,
                          double sigma_along_m, double sigma_across_m)
      : c0_(c0),
        tangent_(tangent.norm() > 1e-9 ? tangent.normalized() : Eigen::Vector3d::Zero()),
        inv_sigma_along_(1.0 / sigma_along_m),
        inv_sigma_across_(1.0 / sigma_across_m) {}

  template <typename T>
  bool operator()(const T* const c, T* residual) const {
    const Eigen::Matrix<T, 3, 1> d(c[0] - T(c0_(0)), c[1] - T(c0_(1)), c[2] - T(c0_(2)));
    const T along = tangent_.cast<T>().dot(d);
    residual[0] = along * T(inv_sigma_along_);
    const Eigen::Matrix<T, 3, 1> across = d - tangent_.cast<T>() * along;
    for (int i = 0; i < 3; ++i) residual[1 + i] = across(i) * T(inv_sigma_across_);
    return true;
  }

  static ceres::CostFunction* Create(const Eigen::Vector3d& c0, const Eigen::Vector3d& tangent,
                                     double sigma_along_m, double sigma_across_m) {
    return new ceres::AutoDiffCostFunction<AlongLaneAnchorResidual, 4, 3>(
        new AlongLaneAnchorResidual(c0, tangent, sigma_along_m, sigma_across_m));
  }

 private:
  Eigen::Vector3d c0_;
  Eigen::Vector3d tangent_;
  double inv_sigma_along_;
  double inv_sigma_across_;
};

}  // namespace residuals
}  // namespace ipm_road_mapper
