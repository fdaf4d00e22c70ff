// Point-to-spline residual, PSR (the baseline of qiao2023online; ablation only). The lane
// pixel's IPM point q (in the map, computed once from the pose and extrinsic at build time,
// so it carries the IPM error) should lie on the spline:
//   r = (S(c0, c1, c2, c3; u) - q) / sigma_m                          (3 residuals)
// with S the uniform Catmull-Rom segment and u the parameter of q's closest spline point,
// fixed when the problem is built. Parameter blocks: c0[3], c1[3], c2[3], c3[3].
#pragma once

#include <ceres/autodiff_cost_function.h>

#include "ipm_road_mapper/core/geometry/catmull_rom_spline.h"

namespace ipm_road_mapper {
namespace residuals {

class PsrResidual {
 public:
  PsrResidual(const Eigen::Vector3d& q_map, double u, double sigma_m)
      : q_map_(q_map), u_(u), inv_sigma_(1.0 / sigma_m) {}

  template <typename T>
  bool operator()(const T* const c0, const T* const c1, const T* const c2, const T* const c3,
                  T* residual) const {
    using V = Eigen::Matrix<T, 3, 1>;
    const V s =
        CatmullRomSpline::EvaluateSegment<T>(V(c0[0], c0[1], c0[2]), V(c1[0], c1[1], c1[2]),
                                             V(c2[0], c2[1], c2[2]), V(c3[0], c3[1], c3[2]), T(u_));
    for (int i = 0; i < 3; ++i) residual[i] = (s(i) - T(q_map_(i))) * T(inv_sigma_);
    return true;
  }

  static ceres::CostFunction* Create(const Eigen::Vector3d& q_map, double u, double sigma_m) {
    return new ceres::AutoDiffCostFunction<PsrResidual, 3, 3, 3, 3, 3>(
        new PsrResidual(q_map, u, sigma_m));
  }

 private:
  Eigen::Vector3d q_map_;
  double u_;
  double inv_sigma_;
};

}  // namespace residuals
}  // namespace ipm_road_mapper
