// Prior that a map point beyond the own lane lies on the road, whose cross-section may bend
// at a crown:
//   r = (n^T (p_map - point) + g kappa) / sigma_m,   g = max(0, |y| - w)      (1 residual)
// (point, n) is the body's plane near the point (road_surface.h), y the point's offset
// across the closest frame's base_link, w = road_crown_lateral_m, and kappa the slope change
// (m/m, > 0: falling away) the road takes beyond w on that side of the vehicle.
//
// Why: a real carriageway is a roof across, falling 1.5-2.5 % each way from a crown at a
// lane line. The vehicle rests on its own side's plane, and the lines across the crown lie
// below it: on av2_pit_dev 9-13 cm 5.2 m out. A camera roll delta and a lateral tilt s of
// the road give the same pixels up to a common lateral shift (delta times the camera
// height), so with every point held to the body's plane extended (RoadSurfacePriorResidual)
// the lines beyond the crown reach their height only by rolling the camera. With this
// residual they reach it through kappa, shared by every point of that side in the solve
// (one tilt for the lines at a place, not a free height each), and the roll is left to what
// lies on the body's plane: the own lane's lines and markings.
//
// Derivation: the surface height above the body's plane at offset y is h(y) = -kappa (|y| -
// w) for |y| > w, so a point on it satisfies n^T (p - point) - h(y) = 0. y moves by
// centimetres in a solve (the points slide along their lines), so g is taken at build time:
//   d r / d p = n^T / sigma_m,   d r / d kappa = g / sigma_m.
// Parameter blocks: p_map[3], kappa[1].
#pragma once

#include <ceres/sized_cost_function.h>

#include "ipm_road_mapper/core/geometry/road_surface.h"

namespace ipm_road_mapper {
namespace residuals {

class RoadCrossSectionPriorResidual : public ceres::SizedCostFunction<1, 3, 1> {
 public:
  RoadCrossSectionPriorResidual(const RoadPlane& plane, double beyond_m, double sigma_m)
      : normal_(plane.normal),
        offset_(plane.normal.dot(plane.point)),
        beyond_m_(beyond_m),
        inv_sigma_(1.0 / sigma_m) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const double* p = parameters[0];
    const double kappa = parameters[1][0];
    residuals[0] = (normal_.x() * p[0] + normal_.y() * p[1] + normal_.z() * p[2] - offset_ +
                    beyond_m_ * kappa) *
                   inv_sigma_;
    if (jacobians && jacobians[0]) {
      for (int i = 0; i < 3; ++i) jacobians[0][i] = normal_(i) * inv_sigma_;
    }
    if (jacobians && jacobians[1]) jacobians[1][0] = beyond_m_ * inv_sigma_;
    return true;
  }

  static ceres::CostFunction* Create(const RoadPlane& plane, double beyond_m, double sigma_m) {
    return new RoadCrossSectionPriorResidual(plane, beyond_m, sigma_m);
  }

 private:
  Eigen::Vector3d normal_;
  double offset_;
  double beyond_m_;
  double inv_sigma_;
};

}  // namespace residuals
}  // namespace ipm_road_mapper
