// Point-to-spline residual, PSR (the baseline of qiao2023online; ablation only). The lane
// pixel's IPM point q (in the map, computed once from the pose and extrinsic at build time,
// so it carries the IPM error) should lie on the spline:
//   r = (S(c0, c1, c2, c3; u) - q) / sigma_m                          (3 residuals)
// with S the uniform Catmull-Rom segment and u the parameter of q's closest spline point,
// fixed when the problem is built. Parameter blocks: c0[3], c1[3], c2[3], c3[3].
//
// The joint binding (PsrJointResidual, the final global solve, where the poses are free):
// the point is the viewing frame's IPM point p_b in base_link, fixed at build time, carried
// by that frame's pose:
//   q = R(q_map_base) p_b + t_map_base
//   r = (S(c0, c1, c2, c3; u) - q) / sigma_m                          (3 residuals)
// so a lane's points move with the poses that see them, as PPSR's pixels do, and the lanes
// constrain the poses through their 3D points (with the IPM error those carry: the ablation's
// point). The extrinsic is not in it: p_b would need the IPM inside the residual, and PSR is
// the baseline of a method that never refines the camera. Parameter blocks: c0[3], c1[3],
// c2[3], c3[3], q_map_base[4] (x, y, z, w), t_map_base[3].
#pragma once

#include <ceres/autodiff_cost_function.h>

#include <Eigen/Geometry>

#include "ipm_road_mapper/core/geometry/catmull_rom_spline.h"

namespace ipm_road_mapper {
namespace residuals {

// The residual, shared by the bindings below: (S(c0, c1, c2, c3; u) - q) * inv_sigma.
template <typename T>
void Psr(const T* const c0, const T* const c1, const T* const c2, const T* const c3, double u,
         const Eigen::Matrix<T, 3, 1>& q, double inv_sigma, T* residual) {
  using V = Eigen::Matrix<T, 3, 1>;
  const V s =
      CatmullRomSpline::EvaluateSegment<T>(V(c0[0], c0[1], c0[2]), V(c1[0], c1[1], c1[2]),
                                           V(c2[0], c2[1], c2[2]), V(c3[0], c3[1], c3[2]), T(u));
  for (int i = 0; i < 3; ++i) residual[i] = (s(i) - q(i)) * T(inv_sigma);
}

class PsrResidual {
 public:
  PsrResidual(const Eigen::Vector3d& q_map, double u, double sigma_m)
      : q_map_(q_map), u_(u), inv_sigma_(1.0 / sigma_m) {}

  template <typename T>
  bool operator()(const T* const c0, const T* const c1, const T* const c2, const T* const c3,
                  T* residual) const {
    Psr(c0, c1, c2, c3, u_, Eigen::Matrix<T, 3, 1>(q_map_.cast<T>()), inv_sigma_, residual);
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

// The joint binding: the point carried by its frame's pose (see the header comment).
class PsrJointResidual {
 public:
  PsrJointResidual(const Eigen::Vector3d& p_base, double u, double sigma_m)
      : p_base_(p_base), u_(u), inv_sigma_(1.0 / sigma_m) {}

  template <typename T>
  bool operator()(const T* const c0, const T* const c1, const T* const c2, const T* const c3,
                  const T* const q_map_base, const T* const t_map_base, T* residual) const {
    using V = Eigen::Matrix<T, 3, 1>;
    const Eigen::Map<const Eigen::Quaternion<T>> q_mb(q_map_base);
    const Eigen::Map<const V> t_mb(t_map_base);
    Psr(c0, c1, c2, c3, u_, V(q_mb * p_base_.cast<T>() + t_mb), inv_sigma_, residual);
    return true;
  }

  static ceres::CostFunction* Create(const Eigen::Vector3d& p_base, double u, double sigma_m) {
    return new ceres::AutoDiffCostFunction<PsrJointResidual, 3, 3, 3, 3, 3, 4, 3>(
        new PsrJointResidual(p_base, u, sigma_m));
  }

 private:
  Eigen::Vector3d p_base_;
  double u_;
  double inv_sigma_;
};

}  // namespace residuals
}  // namespace ipm_road_mapper
