// Smoothness of a lane between three consecutive control points:
//   r = (c_0 - 2 c_1 + c_2) / sigma_m                                   (3 residuals)
// the spline's second difference, about its curvature times the squared spacing (6 cm on
// a 150 m curve with 3 m spacing, so sigma ~ 0.2 m leaves real curves alone). PPSR sees a
// dashed line only on its dashes: a control point in a 6 m gap meets pixels on one side at
// most, and without this term the window's solves let such points wander by decimeters
// (visible as waves on the dashed lines). Parameter blocks: c0[3], c1[3], c2[3].
#pragma once

#include <ceres/sized_cost_function.h>

namespace ipm_road_mapper {
namespace residuals {

class LaneSmoothnessResidual : public ceres::SizedCostFunction<3, 3, 3, 3> {
 public:
  explicit LaneSmoothnessResidual(double sigma_m) : inv_sigma_(1.0 / sigma_m) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    for (int i = 0; i < 3; ++i) {
      residuals[i] = (parameters[0][i] - 2.0 * parameters[1][i] + parameters[2][i]) * inv_sigma_;
    }
    if (!jacobians) return true;
    const double weights[3] = {1.0, -2.0, 1.0};
    for (int b = 0; b < 3; ++b) {
      if (!jacobians[b]) continue;
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c)
          jacobians[b][3 * r + c] = r == c ? weights[b] * inv_sigma_ : 0.0;
      }
    }
    return true;
  }

  static ceres::CostFunction* Create(double sigma_m) { return new LaneSmoothnessResidual(sigma_m); }

 private:
  double inv_sigma_;
};

}  // namespace residuals
}  // namespace ipm_road_mapper
