#include "ipm_road_mapper/core/geometry/principal_axis.h"

#include <Eigen/Eigenvalues>

namespace ipm_road_mapper {

PrincipalAxis HorizontalPrincipalAxis(const std::vector<Eigen::Vector3d>& points) {
  PrincipalAxis axis;
  if (points.empty()) return axis;
  for (const Eigen::Vector3d& p : points) axis.mean += p.head<2>();
  axis.mean /= static_cast<double>(points.size());
  if (points.size() < 2) return axis;
  Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
  for (const Eigen::Vector3d& p : points) {
    const Eigen::Vector2d d = p.head<2>() - axis.mean;
    scatter += d * d.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> solver(scatter);
  axis.direction = solver.eigenvectors().col(1);  // eigenvalues ascending: the larger one's
  axis.scatter = solver.eigenvalues()(1);
  return axis;
}

}  // namespace ipm_road_mapper
