// The road's cross-section prior beyond the own lane (road_cross_section_prior_residual.h)
// and its crown-slope prior: values, Jacobians, and what the shared slope does in a solve.
#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include <memory>

#include "common/residual_scene.h"
#include "ipm_road_mapper/core/backend/residuals/crown_slope_prior_residual.h"
#include "ipm_road_mapper/core/backend/residuals/road_cross_section_prior_residual.h"
#include "ipm_road_mapper/core/backend/residuals/road_surface_prior_residual.h"

namespace ipm_road_mapper {
namespace residuals {
namespace {

// The body's plane through (10, 0, 0.5), tilted 2 % up to the left.
RoadPlane TiltedPlane() {
  RoadPlane plane;
  plane.point = Eigen::Vector3d(10.0, 0.0, 0.5);
  plane.normal = Eigen::Vector3d(0.0, -0.02, 1.0).normalized();
  return plane;
}

TEST(RoadCrossSectionPrior, PassesTheGradientCheck) {
  std::unique_ptr<ceres::CostFunction> cost(
      RoadCrossSectionPriorResidual::Create(TiltedPlane(), 3.25, 0.056));
  const Eigen::Vector3d p(12.0, 5.25, 0.55);
  const double kappa = 0.015;
  ExpectJacobiansMatch(*cost, {nullptr, nullptr}, {p.data(), &kappa}, kGradientPrecision);
  std::unique_ptr<ceres::CostFunction> prior(CrownSlopePriorResidual::Create(0.03));
  ExpectJacobiansMatch(*prior, {nullptr}, {&kappa}, kGradientPrecision);
  EXPECT_NEAR(Evaluate(*prior, {&kappa})(0), 0.5, 1e-12);
}

TEST(RoadCrossSectionPrior, IsZeroOnTheBentPlaneAndThePlanarPriorWithoutACrown) {
  const RoadPlane plane = TiltedPlane();
  const double beyond_m = 3.25, sigma = 0.05;
  std::unique_ptr<ceres::CostFunction> cost(
      RoadCrossSectionPriorResidual::Create(plane, beyond_m, sigma));
  std::unique_ptr<ceres::CostFunction> planar(RoadSurfacePriorResidual::Create(plane, sigma));
  // On the body's plane extended, 5.25 m left: the planar prior's zero, and with kappa = 0
  // the same value.
  const Eigen::Vector3d on_plane(12.0, 5.25, 0.5 + 0.02 * 5.25);
  const double zero = 0.0, kappa = 0.02;
  EXPECT_NEAR(Evaluate(*planar, {on_plane.data()})(0), 0.0, 1e-12);
  EXPECT_NEAR(Evaluate(*cost, {on_plane.data(), &zero})(0), 0.0, 1e-12);
  // 2 % steeper down beyond 2 m: kappa * beyond_m below the body's plane (along its normal)
  // costs nothing with that kappa, and as much as the planar prior says with none.
  const Eigen::Vector3d below = on_plane - kappa * beyond_m * plane.normal;
  EXPECT_NEAR(Evaluate(*cost, {below.data(), &kappa})(0), 0.0, 1e-12);
  EXPECT_NEAR(Evaluate(*cost, {below.data(), &zero})(0), -kappa * beyond_m / sigma, 1e-12);
  EXPECT_NEAR(Evaluate(*cost, {below.data(), &zero})(0), Evaluate(*planar, {below.data()})(0),
              1e-12);
}

// Points of one side share its kappa: three lines beyond the crown, each 2 % x its distance
// past it below the body's plane, held there by their own (stronger) evidence. One kappa
// explains them all, so the prior costs almost nothing; the planar prior would pull each.
TEST(RoadCrossSectionPrior, OneSlopeExplainsEveryPointOfItsSide) {
  RoadPlane plane;  // the body's plane z = 0
  const double sigma = 0.05, evidence_sigma = 0.01, crown = 0.02;
  ceres::Problem problem;
  double kappa = 0.0;
  std::vector<Eigen::Vector3d> points;
  for (double beyond : {1.0, 3.25, 6.75}) points.emplace_back(10.0, 2.0 + beyond, 0.0);
  problem.AddResidualBlock(CrownSlopePriorResidual::Create(0.03), nullptr, &kappa);
  for (Eigen::Vector3d& p : points) {
    const double beyond = p.y() - 2.0;
    problem.AddResidualBlock(RoadCrossSectionPriorResidual::Create(plane, beyond, sigma), nullptr,
                             p.data(), &kappa);
    // The point's own evidence of its height (e.g. its pixels with the camera known).
    const RoadPlane truth{Eigen::Vector3d(0, 0, -crown * beyond), Eigen::Vector3d::UnitZ()};
    problem.AddResidualBlock(RoadSurfacePriorResidual::Create(truth, evidence_sigma), nullptr,
                             p.data());
  }
  ceres::Solver::Options options;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  EXPECT_NEAR(kappa, crown, 0.002);
  for (const Eigen::Vector3d& p : points) EXPECT_NEAR(p.z(), -crown * (p.y() - 2.0), 0.002);
}

}  // namespace
}  // namespace residuals
}  // namespace ipm_road_mapper
