// Prior on the extrinsic translation (paper: || t_b^c - t_0 ||^2_sigma). The translation
// is weakly observable when the vehicle barely rotates (moving the camera or the whole map
// looks alike), so the mounting position t_0 anchors it:
//   r = (t_base_cam - t_0) / sigma_m                                  (3 residuals)
// Parameter block: t_base_cam[3].
#pragma once

#include <ceres/autodiff_cost_function.h>

#include <Eigen/Core>

namespace ipm_road_mapper {
namespace residuals {

class TranslationPriorResidual {
 public:
  TranslationPriorResidual(const Eigen::Vector3d& t0, const Eigen::Vector3d& sigma_m)
      : t0_(t0), inv_sigma_(sigma_m.cwiseInverse()) {}

  template <typename T>
  bool operator()(const T* const t_base_cam, T* residual) const {
    for (int i = 0; i < 3; ++i) residual[i] = (t_base_cam[i] - T(t0_(i))) * T(inv_sigma_(i));
    return true;
  }

  static ceres::CostFunction* Create(const Eigen::Vector3d& t0, const Eigen::Vector3d& sigma_m) {
    return new ceres::AutoDiffCostFunction<TranslationPriorResidual, 3, 3>(
        new TranslationPriorResidual(t0, sigma_m));
  }

 private:
  Eigen::Vector3d t0_;
  Eigen::Vector3d inv_sigma_;
};

}  // namespace residuals
}  // namespace ipm_road_mapper
