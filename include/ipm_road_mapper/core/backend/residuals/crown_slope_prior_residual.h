// Zero-mean prior on a crown's slope change kappa (road_cross_section_prior_residual.h):
//   r = kappa / sigma,   d r / d kappa = 1 / sigma                                (1 residual)
// sigma = road_crown_slope_sigma: how far a road's slope beyond the own lane may differ from
// the body's (design crowns are 1.5-2.5 % each way, so across a crown up to about 4 %).
// Parameter block: kappa[1].
#pragma once

#include <ceres/sized_cost_function.h>

namespace ipm_road_mapper {
namespace residuals {

class CrownSlopePriorResidual : public ceres::SizedCostFunction<1, 1> {
 public:
  explicit CrownSlopePriorResidual(double sigma) : inv_sigma_(1.0 / sigma) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    residuals[0] = parameters[0][0] * inv_sigma_;
    if (jacobians && jacobians[0]) jacobians[0][0] = inv_sigma_;
    return true;
  }

  static ceres::CostFunction* Create(double sigma) { return new CrownSlopePriorResidual(sigma); }

 private:
  double inv_sigma_;
};

}  // namespace residuals
}  // namespace ipm_road_mapper
