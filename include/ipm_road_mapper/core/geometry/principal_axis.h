// The horizontal principal axis of a set of points: the direction along which their x-y
// scatter is largest (the eigenvector of the larger eigenvalue of sum (p - mean)(p - mean)^T).
// A lane's points lie along it (spline_fitting.h orders them by it; lane_join.h compares two
// instances of one frame along it).
#pragma once

#include <Eigen/Core>
#include <vector>

namespace ipm_road_mapper {

struct PrincipalAxis {
  Eigen::Vector2d direction = Eigen::Vector2d::UnitX();  // unit, sign arbitrary
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  double scatter = 0.0;  // the larger eigenvalue, m^2 (0: the points have no extent)
};

// Of `points` (x-y only); a set of fewer than two points has scatter 0 and direction +x.
PrincipalAxis HorizontalPrincipalAxis(const std::vector<Eigen::Vector3d>& points);

}  // namespace ipm_road_mapper
