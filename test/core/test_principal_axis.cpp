// The horizontal principal axis of a point set (principal_axis.h): along a line of points,
// whatever the heights; no extent for one point or none.
#include <gtest/gtest.h>

#include <cmath>

#include "ipm_road_mapper/core/geometry/principal_axis.h"

namespace ipm_road_mapper {
namespace {

TEST(PrincipalAxis, RunsAlongALineOfPointsWhateverTheirHeights) {
  const Eigen::Vector2d d = Eigen::Vector2d(3.0, 4.0).normalized();
  std::vector<Eigen::Vector3d> points;
  for (int k = 0; k < 10; ++k) {
    const Eigen::Vector2d p = Eigen::Vector2d(100.0, -50.0) + 0.5 * k * d;
    // Heights that grow faster than the line does: only x-y counts.
    points.emplace_back(p.x(), p.y(), 2.0 * k + ((k % 2) ? 0.05 : -0.05));
  }
  const PrincipalAxis axis = HorizontalPrincipalAxis(points);
  EXPECT_NEAR(std::abs(axis.direction.dot(d)), 1.0, 1e-9);
  EXPECT_NEAR(axis.direction.norm(), 1.0, 1e-12);
  EXPECT_TRUE(axis.mean.isApprox(Eigen::Vector2d(100.0, -50.0) + 2.25 * d, 1e-12));
  // sum of squared offsets along the line: 0.25 * sum (k - 4.5)^2 = 20.625 m^2.
  EXPECT_NEAR(axis.scatter, 20.625, 1e-9);
}

TEST(PrincipalAxis, OnePointOrNoneHasNoExtent) {
  EXPECT_EQ(HorizontalPrincipalAxis({}).scatter, 0.0);
  const PrincipalAxis one = HorizontalPrincipalAxis({Eigen::Vector3d(1.0, 2.0, 3.0)});
  EXPECT_EQ(one.scatter, 0.0);
  EXPECT_TRUE(one.mean.isApprox(Eigen::Vector2d(1.0, 2.0)));
  // Two equal points: a scatter of 0 as well.
  EXPECT_NEAR(HorizontalPrincipalAxis({Eigen::Vector3d(1, 2, 0), Eigen::Vector3d(1, 2, 5)}).scatter,
              0.0, 1e-12);
}

}  // namespace
}  // namespace ipm_road_mapper
