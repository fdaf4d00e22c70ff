// Tests of the Ceres residuals on the map's elements (docs/design.md §4): the shared
// projection, corner reprojection, PPSR, PSR and lane smoothness; autodiff Jacobians against
// numeric differences (on the quaternion manifold) and values against independently
// computed formulas. The priors: test_pose_residuals; one tiny solve per residual type:
// test_residual_solves.
#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <vector>

#include "common/residual_scene.h"
#include "ipm_road_mapper/core/backend/residuals/corner_reprojection_residual.h"
#include "ipm_road_mapper/core/backend/residuals/lane_smoothness_residual.h"
#include "ipm_road_mapper/core/backend/residuals/ppsr_residual.h"
#include "ipm_road_mapper/core/backend/residuals/projection.h"
#include "ipm_road_mapper/core/backend/residuals/psr_residual.h"
#include "ipm_road_mapper/core/geometry/catmull_rom_spline.h"

namespace ipm_road_mapper {
namespace residuals {
namespace {

// ---------------------------------------------------------------------------------------
// Scene sanity and the shared projection.

TEST_F(ResidualTest, SceneGroundPointsProjectIntoTheImage) {
  for (double x : {8.0, 15.0, 30.0}) {
    for (double y : {-3.0, 0.0, 3.0}) {
      EXPECT_TRUE(camera_.InImage(Project(GroundPoint(x, y)), 10.0)) << x << " " << y;
    }
  }
}

TEST_F(ResidualTest, ProjectMapPointMatchesReferenceProjection) {
  for (double x : {8.0, 12.0, 20.0, 30.0}) {
    for (double y : {-3.0, 0.5, 3.0}) {
      const Eigen::Vector3d p = GroundPoint(x, y);
      Eigen::Vector2d uv;
      ASSERT_TRUE(ProjectMapPoint(camera_, pose_.q.data(), pose_.t.data(), extrinsic_.q.data(),
                                  extrinsic_.t.data(), p, &uv));
      EXPECT_NEAR((uv - Project(p)).norm(), 0.0, 1e-9) << x << " " << y;
    }
  }
}

TEST_F(ResidualTest, ProjectMapPointRejectsPointsBehindTheCamera) {
  Eigen::Vector2d uv;
  EXPECT_FALSE(ProjectMapPoint(camera_, pose_.q.data(), pose_.t.data(), extrinsic_.q.data(),
                               extrinsic_.t.data(), GroundPoint(-5.0, 0.0), &uv));
}

// ---------------------------------------------------------------------------------------
// Corner reprojection.

TEST_F(ResidualTest, CornerReprojectionGradientCheck) {
  const std::vector<const ceres::Manifold*> manifolds = {nullptr, &kQuaternionManifold, nullptr,
                                                         &kQuaternionManifold, nullptr};
  for (double x : {8.0, 12.0, 20.0, 30.0}) {
    for (double y : {-3.0, 2.0}) {
      SCOPED_TRACE(testing::Message() << "ground point " << x << ", " << y);
      const Eigen::Vector3d corner = GroundPoint(x, y);
      const Eigen::Vector2d measured = Project(corner) + Eigen::Vector2d(2.5, -1.5);
      std::unique_ptr<ceres::CostFunction> cost(
          CornerReprojectionResidual::Create(camera_, measured, 1.5));
      ExpectJacobiansMatch(
          *cost, manifolds,
          {corner.data(), pose_.q.data(), pose_.t.data(), extrinsic_.q.data(), extrinsic_.t.data()},
          kGradientPrecision);
    }
  }
}

TEST_F(ResidualTest, CornerReprojectionStepBindingsMatchTheReference) {
  const Eigen::Vector3d corner = GroundPoint(12.0, -1.5);
  const Eigen::Vector2d uv = Project(corner) + Eigen::Vector2d(3.0, -2.0);
  std::unique_ptr<ceres::CostFunction> full(CornerReprojectionResidual::Create(camera_, uv, 2.0));
  const Eigen::VectorXd reference = Evaluate(*full, {corner.data(), pose_.q.data(), pose_.t.data(),
                                                     extrinsic_.q.data(), extrinsic_.t.data()});
  std::unique_ptr<ceres::CostFunction> map_step(
      CornerReprojectionMapStepResidual::Create(camera_, uv, 2.0, pose_.q.data(), pose_.t.data()));
  const std::vector<const double*> map_blocks = {corner.data(), extrinsic_.q.data(),
                                                 extrinsic_.t.data()};
  EXPECT_LT((Evaluate(*map_step, map_blocks) - reference).norm(), 1e-12);
  ExpectJacobiansMatch(*map_step, {nullptr, &kQuaternionManifold, nullptr}, map_blocks,
                       kGradientPrecision);
  std::unique_ptr<ceres::CostFunction> pose_step(CornerReprojectionPoseStepResidual::Create(
      camera_, uv, 2.0, corner, extrinsic_.q.data(), extrinsic_.t.data()));
  const std::vector<const double*> pose_blocks = {pose_.q.data(), pose_.t.data()};
  EXPECT_LT((Evaluate(*pose_step, pose_blocks) - reference).norm(), 1e-12);
  ExpectJacobiansMatch(*pose_step, {&kQuaternionManifold, nullptr}, pose_blocks,
                       kGradientPrecision);
}

TEST_F(ResidualTest, CornerReprojectionIsZeroAtTheTrueProjection) {
  for (double x : {8.0, 15.0, 30.0}) {
    const Eigen::Vector3d corner = GroundPoint(x, -1.0);
    std::unique_ptr<ceres::CostFunction> cost(
        CornerReprojectionResidual::Create(camera_, Project(corner), 2.0));
    const Eigen::VectorXd r = Evaluate(*cost, {corner.data(), pose_.q.data(), pose_.t.data(),
                                               extrinsic_.q.data(), extrinsic_.t.data()});
    EXPECT_NEAR(r.norm(), 0.0, 1e-9) << x;
  }
}

TEST_F(ResidualTest, CornerReprojectionIsTheScaledPixelOffset) {
  const Eigen::Vector3d corner = GroundPoint(14.0, 2.0);
  const Eigen::Vector2d offset(3.0, -4.0);
  const double sigma_px = 2.0;
  std::unique_ptr<ceres::CostFunction> cost(
      CornerReprojectionResidual::Create(camera_, Project(corner) + offset, sigma_px));
  const Eigen::VectorXd r = Evaluate(*cost, {corner.data(), pose_.q.data(), pose_.t.data(),
                                             extrinsic_.q.data(), extrinsic_.t.data()});
  // r = (projected - measured) / sigma.
  EXPECT_NEAR(r(0), -offset(0) / sigma_px, 1e-9);
  EXPECT_NEAR(r(1), -offset(1) / sigma_px, 1e-9);
}

TEST_F(ResidualTest, CornerReprojectionIsInvariantToQuaternionSign) {
  const Eigen::Vector3d corner = GroundPoint(20.0, -2.0);
  std::unique_ptr<ceres::CostFunction> cost(CornerReprojectionResidual::Create(
      camera_, Project(corner) + Eigen::Vector2d(1.0, 2.0), 1.0));
  const PoseBlocks pose_neg = Negated(pose_), extrinsic_neg = Negated(extrinsic_);
  const Eigen::VectorXd r = Evaluate(*cost, {corner.data(), pose_.q.data(), pose_.t.data(),
                                             extrinsic_.q.data(), extrinsic_.t.data()});
  const Eigen::VectorXd r_neg =
      Evaluate(*cost, {corner.data(), pose_neg.q.data(), pose_neg.t.data(), extrinsic_neg.q.data(),
                       extrinsic_neg.t.data()});
  EXPECT_GT(r.norm(), 1.0);
  EXPECT_NEAR((r - r_neg).norm(), 0.0, 1e-9);
}

TEST_F(ResidualTest, CornerReprojectionFailsBehindTheCamera) {
  const Eigen::Vector3d corner = GroundPoint(-5.0, 0.0);
  std::unique_ptr<ceres::CostFunction> cost(
      CornerReprojectionResidual::Create(camera_, Eigen::Vector2d(640.0, 500.0), 1.0));
  const std::vector<const double*> parameters = {corner.data(), pose_.q.data(), pose_.t.data(),
                                                 extrinsic_.q.data(), extrinsic_.t.data()};
  double r[2];
  EXPECT_FALSE(cost->Evaluate(parameters.data(), r, nullptr));
}

// ---------------------------------------------------------------------------------------
// PPSR.

class PpsrTest : public ResidualTest {
 protected:
  Eigen::VectorXd Residual(const Eigen::Vector2d& uv, double sigma_px) const {
    std::unique_ptr<ceres::CostFunction> cost(PpsrResidual::Create(camera_, uv, sigma_px));
    return Evaluate(*cost, {c1_.data(), c2_.data(), pose_.q.data(), pose_.t.data(),
                            extrinsic_.q.data(), extrinsic_.t.data()});
  }

  // A lane segment ahead and to the left, slightly oblique in the image.
  const Eigen::Vector3d c1_ = GroundPoint(10.0, 1.8);
  const Eigen::Vector3d c2_ = GroundPoint(14.0, 2.1);
  const Eigen::Vector2d a_ = Project(c1_);
  const Eigen::Vector2d b_ = Project(c2_);
  const Eigen::Vector2d d_ = (b_ - a_).normalized();
  const Eigen::Vector2d n_ = Eigen::Vector2d(-d_.y(), d_.x());  // unit normal of the segment
};

TEST_F(PpsrTest, GradientCheck) {
  const std::vector<const ceres::Manifold*> manifolds = {
      nullptr, nullptr, &kQuaternionManifold, nullptr, &kQuaternionManifold, nullptr};
  for (double s : {-0.5, 0.3, 0.9}) {
    SCOPED_TRACE(testing::Message() << "s " << s);
    const Eigen::Vector2d uv = a_ + s * (b_ - a_) + 4.0 * n_;
    std::unique_ptr<ceres::CostFunction> cost(PpsrResidual::Create(camera_, uv, 1.5));
    ExpectJacobiansMatch(*cost, manifolds,
                         {c1_.data(), c2_.data(), pose_.q.data(), pose_.t.data(),
                          extrinsic_.q.data(), extrinsic_.t.data()},
                         kGradientPrecision);
  }
}

// The step bindings compute the reference residual with some blocks held as data, and
// their Jacobians (only the free blocks) pass the gradient check too.
TEST_F(PpsrTest, StepBindingsMatchTheReferenceAndPassGradientChecks) {
  const Eigen::Vector2d uv = a_ + 0.4 * (b_ - a_) + 3.0 * n_;
  const Eigen::VectorXd reference = Residual(uv, 1.5);
  std::unique_ptr<ceres::CostFunction> map_step(
      PpsrMapStepResidual::Create(camera_, uv, 1.5, pose_.q.data(), pose_.t.data()));
  const std::vector<const double*> map_blocks = {c1_.data(), c2_.data(), extrinsic_.q.data(),
                                                 extrinsic_.t.data()};
  EXPECT_LT((Evaluate(*map_step, map_blocks) - reference).norm(), 1e-12);
  ExpectJacobiansMatch(*map_step, {nullptr, nullptr, &kQuaternionManifold, nullptr}, map_blocks,
                       kGradientPrecision);
  std::unique_ptr<ceres::CostFunction> pose_step(PpsrPoseStepResidual::Create(
      camera_, uv, 1.5, c1_, c2_, extrinsic_.q.data(), extrinsic_.t.data()));
  const std::vector<const double*> pose_blocks = {pose_.q.data(), pose_.t.data()};
  EXPECT_LT((Evaluate(*pose_step, pose_blocks) - reference).norm(), 1e-12);
  ExpectJacobiansMatch(*pose_step, {&kQuaternionManifold, nullptr}, pose_blocks,
                       kGradientPrecision);
}

TEST_F(PpsrTest, IsZeroOnTheLineThroughTheProjectedControlPoints) {
  ASSERT_GT((b_ - a_).norm(), 20.0);  // a real segment, not a degenerate one
  for (double s : {-5.0, -1.0, 0.0, 0.25, 0.5, 1.0, 3.0, 10.0}) {
    EXPECT_NEAR(Residual(a_ + s * (b_ - a_), 1.0).norm(), 0.0, 1e-9) << s;
  }
}

TEST_F(PpsrTest, IsThePerpendicularPixelDistanceOverSigma) {
  const double sigma_px = 2.5;
  for (double distance : {-7.0, 0.5, 3.0}) {
    const Eigen::Vector2d uv = a_ + 0.4 * (b_ - a_) + distance * n_;
    const Eigen::VectorXd r = Residual(uv, sigma_px);
    EXPECT_NEAR(r.norm(), std::abs(distance) / sigma_px, 1e-9) << distance;
    // r = (I - d d^T)(a - z) = -distance * n / sigma: along the normal, pointing back.
    EXPECT_NEAR((r - Eigen::Vector2d(-distance * n_ / sigma_px)).norm(), 0.0, 1e-9) << distance;
    EXPECT_NEAR(r.dot(d_), 0.0, 1e-9);
  }
}

TEST_F(PpsrTest, IsUnchangedByAnOffsetAlongTheSegment) {
  const Eigen::Vector2d uv = a_ + 0.3 * (b_ - a_) + 5.0 * n_;
  const Eigen::VectorXd r = Residual(uv, 1.0);
  ASSERT_GT(r.norm(), 4.9);
  for (double along : {-40.0, -3.0, 7.5, 60.0}) {
    EXPECT_NEAR((Residual(uv + along * d_, 1.0) - r).norm(), 0.0, 1e-9) << along;
  }
}

TEST_F(PpsrTest, IsInvariantToQuaternionSign) {
  const Eigen::Vector2d uv = a_ + 0.6 * (b_ - a_) + 3.0 * n_;
  std::unique_ptr<ceres::CostFunction> cost(PpsrResidual::Create(camera_, uv, 1.0));
  const PoseBlocks pose_neg = Negated(pose_), extrinsic_neg = Negated(extrinsic_);
  const Eigen::VectorXd r = Evaluate(*cost, {c1_.data(), c2_.data(), pose_.q.data(), pose_.t.data(),
                                             extrinsic_.q.data(), extrinsic_.t.data()});
  const Eigen::VectorXd r_neg =
      Evaluate(*cost, {c1_.data(), c2_.data(), pose_neg.q.data(), pose_neg.t.data(),
                       extrinsic_neg.q.data(), extrinsic_neg.t.data()});
  EXPECT_NEAR(r.norm(), 3.0, 1e-9);
  EXPECT_NEAR((r - r_neg).norm(), 0.0, 1e-9);
}

TEST_F(PpsrTest, FailsForCoincidentProjectedControlPoints) {
  std::unique_ptr<ceres::CostFunction> cost(PpsrResidual::Create(camera_, a_, 1.0));
  const std::vector<const double*> parameters = {c1_.data(),          c1_.data(),
                                                 pose_.q.data(),      pose_.t.data(),
                                                 extrinsic_.q.data(), extrinsic_.t.data()};
  double r[2];
  EXPECT_FALSE(cost->Evaluate(parameters.data(), r, nullptr));
}

// ---------------------------------------------------------------------------------------
// PSR.

// The Catmull-Rom segment as a cubic Hermite curve from c1 to c2 with tangents
// (c2 - c0) / 2 and (c3 - c1) / 2, independent of CatmullRomSpline's polynomial form.
Eigen::Vector3d HermiteCatmullRom(const Eigen::Vector3d& c0, const Eigen::Vector3d& c1,
                                  const Eigen::Vector3d& c2, const Eigen::Vector3d& c3, double u) {
  const double u2 = u * u, u3 = u2 * u;
  const double h00 = 2 * u3 - 3 * u2 + 1, h10 = u3 - 2 * u2 + u;
  const double h01 = -2 * u3 + 3 * u2, h11 = u3 - u2;
  return h00 * c1 + h10 * 0.5 * (c2 - c0) + h01 * c2 + h11 * 0.5 * (c3 - c1);
}

class PsrTest : public ::testing::Test {
 protected:
  Eigen::VectorXd Residual(const Eigen::Vector3d& q, double u, double sigma_m) const {
    std::unique_ptr<ceres::CostFunction> cost(PsrResidual::Create(q, u, sigma_m));
    return Evaluate(*cost, {c_[0].data(), c_[1].data(), c_[2].data(), c_[3].data()});
  }

  // A curving, slightly non-planar lane in the map.
  const std::array<Eigen::Vector3d, 4> c_ = {
      Eigen::Vector3d(20.0, 5.0, 0.1), Eigen::Vector3d(23.0, 6.2, 0.15),
      Eigen::Vector3d(25.5, 8.4, 0.1), Eigen::Vector3d(27.0, 11.5, 0.0)};
};

TEST_F(PsrTest, GradientCheck) {
  const std::vector<const ceres::Manifold*> manifolds(4, nullptr);
  for (double u : {0.0, 0.37, 1.0}) {
    SCOPED_TRACE(testing::Message() << "u " << u);
    const Eigen::Vector3d q =
        HermiteCatmullRom(c_[0], c_[1], c_[2], c_[3], u) + Eigen::Vector3d(0.2, -0.3, 0.05);
    std::unique_ptr<ceres::CostFunction> cost(PsrResidual::Create(q, u, 0.2));
    ExpectJacobiansMatch(*cost, manifolds, {c_[0].data(), c_[1].data(), c_[2].data(), c_[3].data()},
                         kGradientPrecision);
  }
}

TEST_F(PsrTest, IsZeroForAPointOnTheSplineAtU) {
  const CatmullRomSpline spline({c_[0], c_[1], c_[2], c_[3]});
  for (double u : {0.0, 0.2, 0.37, 0.5, 0.81, 1.0}) {
    const Eigen::Vector3d q = HermiteCatmullRom(c_[0], c_[1], c_[2], c_[3], u);
    EXPECT_NEAR((spline.Evaluate(u) - q).norm(), 0.0, 1e-12) << u;
    EXPECT_NEAR(Residual(q, u, 0.3).norm(), 0.0, 1e-12) << u;
  }
}

TEST_F(PsrTest, IsTheScaledOffset) {
  const double u = 0.63, sigma_m = 0.25;
  const Eigen::Vector3d offset(0.1, -0.2, 0.05);
  const Eigen::Vector3d q = HermiteCatmullRom(c_[0], c_[1], c_[2], c_[3], u) + offset;
  // r = (S(u) - q) / sigma.
  EXPECT_NEAR((Residual(q, u, sigma_m) - Eigen::VectorXd(-offset / sigma_m)).norm(), 0.0, 1e-12);
}

TEST_F(PsrTest, UsesTheFixedParameterNotTheClosestPoint) {
  // q on the spline at u = 0.3 but the residual built for u = 0.7: the spline point there
  // is meters away, so the residual must not be zero.
  const Eigen::Vector3d q = HermiteCatmullRom(c_[0], c_[1], c_[2], c_[3], 0.3);
  const Eigen::Vector3d s = HermiteCatmullRom(c_[0], c_[1], c_[2], c_[3], 0.7);
  EXPECT_NEAR((Residual(q, 0.7, 1.0) - Eigen::VectorXd(s - q)).norm(), 0.0, 1e-12);
}

// The joint binding: the frame's IPM point carried by its pose.
TEST_F(PsrTest, JointBindingIsThePointCarriedByThePoseAndPassesTheGradientCheck) {
  const Eigen::Quaterniond q_map_base =
      Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()) *
                         Eigen::AngleAxisd(0.02, Eigen::Vector3d::UnitX()))
          .normalized();
  const Eigen::Vector3d t_map_base(12.0, -3.0, 0.4);
  const Eigen::Vector3d p_base(9.0, 1.5, -0.02);
  const Eigen::Vector3d q_map = q_map_base * p_base + t_map_base;
  const double u = 0.41, sigma_m = 0.2;
  std::unique_ptr<ceres::CostFunction> joint(PsrJointResidual::Create(p_base, u, sigma_m));
  const std::vector<const double*> parameters = {
      c_[0].data(),     c_[1].data(), c_[2].data(), c_[3].data(), q_map_base.coeffs().data(),
      t_map_base.data()};
  // The same residual as the build-time point in the map.
  EXPECT_NEAR((Evaluate(*joint, parameters) - Residual(q_map, u, sigma_m)).norm(), 0.0, 1e-12);
  // Moving the pose moves the point: 0.1 m of t along y is -0.1 / sigma in r_y.
  const Eigen::Vector3d t_moved = t_map_base + Eigen::Vector3d(0.0, 0.1, 0.0);
  const Eigen::VectorXd r_moved =
      Evaluate(*joint, {c_[0].data(), c_[1].data(), c_[2].data(), c_[3].data(),
                        q_map_base.coeffs().data(), t_moved.data()});
  EXPECT_NEAR(r_moved(1) - Residual(q_map, u, sigma_m)(1), -0.1 / sigma_m, 1e-12);
  // In the quaternion's raw coefficients: in the manifold's tangent (a left rotation) the
  // Jacobian of R p is -[R p]x / sigma, whose diagonal is zero exactly and which the
  // numeric differences meet only to 1e-14, not to a relative precision.
  ExpectJacobiansMatch(*joint, std::vector<const ceres::Manifold*>(6, nullptr), parameters,
                       kGradientPrecision);
}

// ---------------------------------------------------------------------------------------
// Lane smoothness.

TEST(LaneSmoothnessResidualTest, IsTheScaledSecondDifferenceAndPassesTheGradientCheck) {
  const Eigen::Vector3d c0(0, 0, 0), c1(3, 0.1, 0.0), c2(6, 0.3, 0.05);
  std::unique_ptr<ceres::CostFunction> cost(residuals::LaneSmoothnessResidual::Create(0.2));
  const Eigen::VectorXd r = Evaluate(*cost, {c0.data(), c1.data(), c2.data()});
  EXPECT_LT((r - (c0 - 2.0 * c1 + c2) / 0.2).norm(), 1e-12);
  ExpectJacobiansMatch(*cost, {nullptr, nullptr, nullptr}, {c0.data(), c1.data(), c2.data()},
                       kGradientPrecision);
  // Evenly spaced points on a line cost nothing.
  const Eigen::Vector3d d2(6, 0.2, 0.0);
  EXPECT_LT(Evaluate(*cost, {c0.data(), c1.data(), d2.data()}).norm(), 1e-12);
}

}  // namespace
}  // namespace residuals
}  // namespace ipm_road_mapper
