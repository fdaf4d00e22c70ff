// Prior that a map point lies on the road:
//   r = n^T (p_map - point) / sigma_m                                  (1 residual)
// with (point, n) the road's plane near the point, from the vehicle's poses (road_surface.h),
// and sigma growing with how far that plane is extrapolated. Why: a lane seen by a camera
// driving along it is only known to lie in the plane through the camera's path and the
// line of sight, so without the road its height and lateral offset trade freely; the
// extrinsic roll about the direction of travel is likewise unobservable from reprojection
// alone on straight roads, and the road's height under the wheels fixes the camera's.
// Parameter block: p_map[3].
#pragma once

#include <ceres/sized_cost_function.h>

#include "ipm_road_mapper/core/geometry/road_surface.h"

namespace ipm_road_mapper {
namespace residuals {

class RoadSurfacePriorResidual : public ceres::SizedCostFunction<1, 3> {
 public:
  RoadSurfacePriorResidual(const RoadPlane& plane, double sigma_m)
      : normal_(plane.normal), offset_(plane.normal.dot(plane.point)), inv_sigma_(1.0 / sigma_m) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const double* p = parameters[0];
    residuals[0] =
        (normal_.x() * p[0] + normal_.y() * p[1] + normal_.z() * p[2] - offset_) * inv_sigma_;
    if (jacobians && jacobians[0]) {
      for (int i = 0; i < 3; ++i) jacobians[0][i] = normal_(i) * inv_sigma_;
    }
    return true;
  }

  static ceres::CostFunction* Create(const RoadPlane& plane, double sigma_m) {
    return new RoadSurfacePriorResidual(plane, sigma_m);
  }

 private:
  Eigen::Vector3d normal_;
  double offset_;
  double inv_sigma_;
};

}  // namespace residuals
}  // namespace ipm_road_mapper
