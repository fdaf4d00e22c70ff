// Tests of the Ceres residuals of the map and pose optimization (docs/design.md §4):
// autodiff Jacobians against numeric differences (on the quaternion manifold), values
// against independently computed formulas, and one tiny solve per residual type.
#include <ceres/ceres.h>
#include <ceres/gradient_checker.h>
#include <ceres/manifold.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <iostream>
#include <memory>
#include <vector>

#include "common/test_scene.h"
#include "ipm_road_mapper/core/backend/residuals/corner_reprojection_residual.h"
#include "ipm_road_mapper/core/backend/residuals/lane_smoothness_residual.h"
#include "ipm_road_mapper/core/backend/residuals/motion_prior_residual.h"
#include "ipm_road_mapper/core/backend/residuals/pose_prior_residual.h"
#include "ipm_road_mapper/core/backend/residuals/ppsr_residual.h"
#include "ipm_road_mapper/core/backend/residuals/projection.h"
#include "ipm_road_mapper/core/backend/residuals/psr_residual.h"
#include "ipm_road_mapper/core/geometry/catmull_rom_spline.h"
#include "ipm_road_mapper/core/geometry/ipm.h"
#include "ipm_road_mapper/core/geometry/pinhole_camera.h"
#include "ipm_road_mapper/core/geometry/rigid_transform.h"

namespace ipm_road_mapper {
namespace residuals {
namespace {

constexpr double kDeg = M_PI / 180.0;
// Relative precision of the gradient checks. The residuals never run the distortion's
// Newton inversion (only the forward model), so autodiff and Ridders' differences agree
// far below this (worst observed: 7e-10 for the corner reprojection, 2e-12 for PPSR,
// 1e-13 for PSR and the priors).
constexpr double kGradientPrecision = 1e-7;

// ---------------------------------------------------------------------------------------
// Scene: 1280x720 camera with mild plumb_bob distortion, 1.5 m high and 1.5 m ahead of
// base_link, looking forward and pitched down 5 deg; a vehicle pose with yaw and
// translation (and a little roll and pitch, so no axis is special); ground points ahead.

PinholeCamera TestCamera() {
  return PinholeCamera(test::Intrinsics1280x720(640.0, 360.0, test::kMildDistortion));
}

Eigen::Isometry3d Extrinsic(double pitch_rad) { return test::MountedCamera(0.0, pitch_rad, 0.0); }

// Pitch of the camera rig encoded in an extrinsic rotation (inverse of Extrinsic()).
double ExtrinsicPitch(const Eigen::Matrix3d& R_base_cam) {
  return RpyFromRotation(R_base_cam * test::BaseOpticalAxes().transpose())(1);
}

Eigen::Isometry3d VehiclePose() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = RotationFromRpy(1.0 * kDeg, -2.0 * kDeg, 35.0 * kDeg);
  T.translation() = Eigen::Vector3d(12.0, -4.0, 0.4);
  return T;
}

// A transform as Ceres parameter blocks: quaternion (x, y, z, w) and translation.
struct PoseBlocks {
  std::array<double, 4> q{};
  std::array<double, 3> t{};
};

PoseBlocks ToBlocks(const Eigen::Isometry3d& T) {
  PoseBlocks blocks;
  Eigen::Map<Eigen::Vector4d>(blocks.q.data()) = Eigen::Quaterniond(T.linear()).coeffs();
  Eigen::Map<Eigen::Vector3d>(blocks.t.data()) = T.translation();
  return blocks;
}

PoseBlocks Negated(const PoseBlocks& blocks) {
  PoseBlocks negated = blocks;
  for (double& c : negated.q) c = -c;
  return negated;
}

Eigen::Isometry3d FromBlocks(const PoseBlocks& blocks) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Quaterniond(blocks.q[3], blocks.q[0], blocks.q[1], blocks.q[2])
                   .normalized()
                   .toRotationMatrix();
  T.translation() = Eigen::Vector3d(blocks.t[0], blocks.t[1], blocks.t[2]);
  return T;
}

// Reference projection, written without projection.h: p_cam = T_cam_base T_base_map p.
Eigen::Vector2d ReferenceProjection(const PinholeCamera& camera,
                                    const Eigen::Isometry3d& T_map_base,
                                    const Eigen::Isometry3d& T_base_cam,
                                    const Eigen::Vector3d& p_map) {
  const Eigen::Vector3d p_cam = (T_base_cam.inverse() * T_map_base.inverse()) * p_map;
  Eigen::Vector2d uv;
  EXPECT_TRUE(camera.Project(p_cam, &uv));
  return uv;
}

// Residuals of a cost function at `parameters` (no Jacobians).
Eigen::VectorXd Evaluate(const ceres::CostFunction& cost,
                         const std::vector<const double*>& parameters) {
  Eigen::VectorXd residuals(cost.num_residuals());
  EXPECT_TRUE(cost.Evaluate(parameters.data(), residuals.data(), nullptr));
  return residuals;
}

// Compares the autodiff Jacobians with Ridders' differences, in the manifolds' tangent
// spaces (nullptr: Euclidean block).
void ExpectJacobiansMatch(const ceres::CostFunction& cost,
                          const std::vector<const ceres::Manifold*>& manifolds,
                          const std::vector<const double*>& parameters, double relative_precision) {
  ASSERT_EQ(manifolds.size(), cost.parameter_block_sizes().size());
  ASSERT_EQ(parameters.size(), cost.parameter_block_sizes().size());
  ceres::NumericDiffOptions options;
  // Ridders' first step is this fraction of |x|. The default, 1e-2, is 0.2-0.4 m for map
  // coordinates of 20-40 m, where the projection is too nonlinear for the extrapolation
  // (it stops early with errors up to 100 %); 1e-3 still leaves it room to extrapolate.
  options.ridders_relative_initial_step_size = 1e-3;
  const ceres::GradientChecker checker(&cost, &manifolds, options);
  ceres::GradientChecker::ProbeResults results;
  EXPECT_TRUE(checker.Probe(parameters.data(), relative_precision, &results)) << results.error_log;
  EXPECT_TRUE(results.return_value);
  // The point of a gradient check is lost if every Jacobian entry is zero.
  double largest_entry = 0.0;
  for (const auto& jacobian : results.local_jacobians) {
    largest_entry = std::max(largest_entry, jacobian.cwiseAbs().maxCoeff());
  }
  EXPECT_GT(largest_entry, 1e-3);
}

const ceres::EigenQuaternionManifold kQuaternionManifold;

class ResidualTest : public ::testing::Test {
 protected:
  // Point on the ground of the vehicle (z = 0 in base_link), in the map.
  Eigen::Vector3d GroundPoint(double x_ahead, double y_left) const {
    return T_map_base_ * Eigen::Vector3d(x_ahead, y_left, 0.0);
  }

  Eigen::Vector2d Project(const Eigen::Vector3d& p_map) const {
    return ReferenceProjection(camera_, T_map_base_, T_base_cam_, p_map);
  }

  const PinholeCamera camera_ = TestCamera();
  const Eigen::Isometry3d T_base_cam_ = Extrinsic(5.0 * kDeg);
  const Eigen::Isometry3d T_map_base_ = VehiclePose();
  const PoseBlocks pose_ = ToBlocks(T_map_base_);
  const PoseBlocks extrinsic_ = ToBlocks(T_base_cam_);
};

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

// ---------------------------------------------------------------------------------------
// Pose prior.

class PosePriorTest : public ::testing::Test {
 protected:
  Eigen::VectorXd Residual(const PoseBlocks& pose) const {
    std::unique_ptr<ceres::CostFunction> cost(
        PosePriorResidual::Create(T_prior_, sigma_trans_, sigma_rot_));
    return Evaluate(*cost, {pose.q.data(), pose.t.data()});
  }

  // Yawed 90 deg (plus a little roll and pitch), so base x is map y: a residual computed
  // in the map frame instead of the prior's base frame fails.
  const Eigen::Isometry3d T_prior_ = [] {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = RotationFromRpy(2.0 * kDeg, -3.0 * kDeg, 90.0 * kDeg);
    T.translation() = Eigen::Vector3d(40.0, -12.0, 1.0);
    return T;
  }();
  // Anisotropic, so that swapped axes fail too.
  const Eigen::Vector3d sigma_trans_ = Eigen::Vector3d(0.5, 0.2, 0.1);
  const Eigen::Vector3d sigma_rot_ = Eigen::Vector3d(0.01, 0.02, 0.05);
};

TEST_F(PosePriorTest, GradientCheck) {
  // A prior without the exact 90 deg yaw: its cos(yaw) = 6e-17 Jacobian entries are pure
  // rounding on both sides, which the checker's relative test cannot compare.
  Eigen::Isometry3d T_prior = Eigen::Isometry3d::Identity();
  T_prior.linear() = RotationFromRpy(4.0 * kDeg, -6.0 * kDeg, 70.0 * kDeg);
  T_prior.translation() = Eigen::Vector3d(40.0, -12.0, 1.0);
  std::unique_ptr<ceres::CostFunction> cost(
      PosePriorResidual::Create(T_prior, sigma_trans_, sigma_rot_));
  const std::vector<const ceres::Manifold*> manifolds = {&kQuaternionManifold, nullptr};
  const Eigen::Isometry3d deltas[] = {
      ExpSe3((Vector6d() << 0.3, -0.2, 0.1, 0.02, -0.03, 0.05).finished()),
      ExpSe3((Vector6d() << -1.0, 0.5, 0.2, 0.3, 0.2, -0.4).finished()),
      ExpSe3((Vector6d() << 0.01, 0.004, -0.002, 1e-4, -2e-4, 3e-4).finished())};
  for (const Eigen::Isometry3d& delta : deltas) {
    const PoseBlocks pose = ToBlocks(T_prior * delta);
    ExpectJacobiansMatch(*cost, manifolds, {pose.q.data(), pose.t.data()}, kGradientPrecision);
  }
}

TEST_F(PosePriorTest, IsZeroAtThePrior) {
  EXPECT_NEAR(Residual(ToBlocks(T_prior_)).norm(), 0.0, 1e-12);
  EXPECT_NEAR(Residual(Negated(ToBlocks(T_prior_))).norm(), 0.0, 1e-12);
}

TEST_F(PosePriorTest, TranslationIsExpressedInThePriorsBaseFrame) {
  const Eigen::Vector3d dt_base(0.3, -0.1, 0.05);
  Eigen::Isometry3d T = T_prior_;
  T.translation() += T_prior_.linear() * dt_base;  // shift along the prior's own axes
  const Eigen::VectorXd r = Residual(ToBlocks(T));
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(r(i), dt_base(i) / sigma_trans_(i), 1e-9) << i;
    EXPECT_NEAR(r(3 + i), 0.0, 1e-9) << i;
  }
  // A shift along map x is, with the 90 deg yaw, (about) a shift along base -y.
  Eigen::Isometry3d T_map_x = T_prior_;
  T_map_x.translation().x() += 1.0;
  const Eigen::VectorXd r_map_x = Residual(ToBlocks(T_map_x));
  const Eigen::Vector3d expected = T_prior_.linear().transpose() * Eigen::Vector3d::UnitX();
  ASSERT_NEAR(expected.y(), -1.0, 0.01);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(r_map_x(i), expected(i) / sigma_trans_(i), 1e-9) << i;
}

TEST_F(PosePriorTest, SmallRotationAboutEachBaseAxisGivesAngleOverSigma) {
  for (int axis = 0; axis < 3; ++axis) {
    for (double angle : {0.01, -0.004}) {
      SCOPED_TRACE(testing::Message() << "axis " << axis << " angle " << angle);
      Eigen::Isometry3d T = T_prior_;
      T.linear() = T_prior_.linear() * Eigen::AngleAxisd(angle, Eigen::Vector3d::Unit(axis));
      const Eigen::VectorXd r = Residual(ToBlocks(T));
      for (int i = 0; i < 3; ++i) {
        EXPECT_NEAR(r(i), 0.0, 1e-9);
        const double expected = (i == axis) ? angle / sigma_rot_(i) : 0.0;
        // 2 sin(angle / 2) vs angle: relative difference angle^2 / 24.
        EXPECT_NEAR(r(3 + i), expected, 1e-5 * std::abs(expected) + 1e-9);
      }
    }
  }
}

TEST_F(PosePriorTest, IsInvariantToQuaternionSign) {
  const Eigen::Isometry3d deltas[] = {
      ExpSe3((Vector6d() << 0.3, -0.2, 0.1, 0.02, -0.03, 0.05).finished()),
      ExpSe3((Vector6d() << -1.0, 0.5, 0.0, 0.3, 0.2, -0.4).finished())};
  for (const Eigen::Isometry3d& delta : deltas) {
    const PoseBlocks pose = ToBlocks(T_prior_ * delta);
    const Eigen::VectorXd r = Residual(pose);
    const Eigen::VectorXd r_neg = Residual(Negated(pose));
    EXPECT_GT(r.tail<3>().norm(), 1.0);
    EXPECT_NEAR((r - r_neg).norm(), 0.0, 1e-9);
  }
}

// ---------------------------------------------------------------------------------------
// Motion prior.

class MotionPriorTest : public ::testing::Test {
 protected:
  Eigen::VectorXd Residual(const std::array<PoseBlocks, 3>& p) const {
    std::unique_ptr<ceres::CostFunction> cost(
        MotionPriorResidual::Create(dt_a_, dt_b_, sigma_acc_, sigma_ang_));
    return Evaluate(*cost, {p[0].q.data(), p[0].t.data(), p[1].q.data(), p[1].t.data(),
                            p[2].q.data(), p[2].t.data()});
  }
  // Unequal steps and anisotropic sigmas, so that a swapped dt or axis fails.
  const double dt_a_ = 0.05, dt_b_ = 0.06;
  const Eigen::Vector3d sigma_acc_ = Eigen::Vector3d(1.0, 2.0, 4.0);
  const Eigen::Vector3d sigma_ang_ = Eigen::Vector3d(0.5, 0.25, 0.125);
};

TEST_F(MotionPriorTest, IsZeroForConstantVelocityAndConstantTurnRate) {
  // Straight map-frame velocity while the body yaws at a constant rate (the two parts are
  // independent in the finite differences, so this is the exact zero of the residual).
  const Eigen::Vector3d v(8.0, 3.0, 0.2);
  const double yaw_rate = 0.3, pitch = 2.0 * kDeg;
  std::array<PoseBlocks, 3> p;
  const double t[3] = {0.0, dt_a_, dt_a_ + dt_b_};
  for (int i = 0; i < 3; ++i) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = RotationFromRpy(0.0, pitch, 0.4 + yaw_rate * t[i]);
    T.translation() = Eigen::Vector3d(5.0, -2.0, 0.3) + v * t[i];
    p[i] = ToBlocks(T);
  }
  EXPECT_LT(Residual(p).norm(), 1e-9);
  p[1] = Negated(p[1]);  // the quaternion sign means nothing
  EXPECT_LT(Residual(p).norm(), 1e-9);
}

TEST_F(MotionPriorTest, IsTheAccelerationInTheMiddleBaseFrameOverSigma) {
  // The middle pose yawed 90 deg: map x is base -y. Acceleration a along map x.
  const double dt = 0.5 * (dt_a_ + dt_b_);
  const Eigen::Vector3d a_map(1.5, 0.0, 0.0);
  const Eigen::Vector3d v0(10.0, 0.0, 0.0);
  const Eigen::Vector3d t0(0, 0, 0), t1 = t0 + v0 * dt_a_, t2 = t1 + (v0 + a_map * dt) * dt_b_;
  std::array<PoseBlocks, 3> p;
  const Eigen::Vector3d ts[3] = {t0, t1, t2};
  for (int i = 0; i < 3; ++i) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = RotationFromRpy(0.0, 0.0, M_PI / 2);
    T.translation() = ts[i];
    p[i] = ToBlocks(T);
  }
  const Eigen::VectorXd r = Residual(p);
  EXPECT_NEAR(r(0), 0.0, 1e-9);
  EXPECT_NEAR(r(1), -1.5 / sigma_acc_(1), 1e-9);
  EXPECT_NEAR(r(2), 0.0, 1e-9);
  EXPECT_LT(r.tail<3>().norm(), 1e-9);
}

TEST_F(MotionPriorTest, IsTheChangeOfTurnRateOverSigma) {
  // Yaw rate 0.1 rad/s, then 0.2 rad/s, translation still: the base z row carries it.
  const double dt = 0.5 * (dt_a_ + dt_b_);
  const double yaw[3] = {0.0, 0.1 * dt_a_, 0.1 * dt_a_ + 0.2 * dt_b_};
  std::array<PoseBlocks, 3> p;
  for (int i = 0; i < 3; ++i) p[i] = ToBlocks(test::PlanarPose(1.0, 2.0, yaw[i]));
  const Eigen::VectorXd r = Residual(p);
  EXPECT_LT(r.head<3>().norm(), 1e-9);
  EXPECT_NEAR(r(5), 0.1 / (dt * sigma_ang_(2)), 1e-9);
  EXPECT_NEAR(r(3), 0.0, 1e-9);
  EXPECT_NEAR(r(4), 0.0, 1e-9);
}

TEST_F(MotionPriorTest, GradientCheck) {
  std::unique_ptr<ceres::CostFunction> cost(
      MotionPriorResidual::Create(dt_a_, dt_b_, sigma_acc_, sigma_ang_));
  const PoseBlocks p0 = ToBlocks(VehiclePose());
  const PoseBlocks p1 = ToBlocks(
      VehiclePose() * ExpSe3((Vector6d() << 0.5, 0.02, 0.01, 0.003, -0.002, 0.02).finished()));
  const PoseBlocks p2 = ToBlocks(
      VehiclePose() * ExpSe3((Vector6d() << 1.1, -0.03, 0.02, -0.004, 0.003, 0.05).finished()));
  const std::vector<const ceres::Manifold*> manifolds = {
      &kQuaternionManifold, nullptr, &kQuaternionManifold, nullptr, &kQuaternionManifold, nullptr};
  ExpectJacobiansMatch(
      *cost, manifolds,
      {p0.q.data(), p0.t.data(), p1.q.data(), p1.t.data(), p2.q.data(), p2.t.data()},
      kGradientPrecision);
}

// ---------------------------------------------------------------------------------------
// Tiny solves, one per residual type.

ceres::Solver::Options TightSolverOptions() {
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = 200;
  options.function_tolerance = 1e-16;
  options.gradient_tolerance = 1e-16;
  options.parameter_tolerance = 1e-14;
  return options;
}

// Five poses on a gently turning path (yaw and lateral motion make the extrinsic
// rotation observable).
std::vector<Eigen::Isometry3d> DrivePoses() {
  std::vector<Eigen::Isometry3d> poses;
  for (int i = 0; i < 5; ++i)
    poses.push_back(test::PlanarPose(2.0 * i, 0.07 * i * i, 3.0 * kDeg * i));
  return poses;
}

TEST(ResidualSolveTest, CornersAndExtrinsicRotationRecoverThePitch) {
  const PinholeCamera camera = TestCamera();
  const Eigen::Isometry3d T_true = Extrinsic(5.0 * kDeg);
  const Eigen::Isometry3d T_wrong = Extrinsic(5.5 * kDeg);
  const std::vector<Eigen::Isometry3d> poses = DrivePoses();
  const std::vector<Eigen::Vector3d> corners_true = {
      {16.0, 2.0, 0.0}, {22.0, -1.0, 0.0}, {30.0, 3.5, 0.0}};

  // Corners initialized by flat-ground IPM of their first-frame pixels with the wrong
  // extrinsic: off by meters.
  const Ipm ipm_wrong(camera, T_wrong, 100.0);
  std::vector<Eigen::Vector3d> corners;
  for (const Eigen::Vector3d& p : corners_true) {
    Eigen::Vector3d p_base;
    ASSERT_EQ(ipm_wrong.PixelToGround(ReferenceProjection(camera, poses[0], T_true, p), &p_base),
              IpmStatus::kOk);
    corners.push_back(poses[0] * p_base);
  }
  EXPECT_GT((corners[2] - corners_true[2]).norm(), 1.0);

  std::vector<PoseBlocks> pose_blocks;
  for (const Eigen::Isometry3d& T : poses) pose_blocks.push_back(ToBlocks(T));
  PoseBlocks extrinsic = ToBlocks(T_wrong);

  ceres::Problem problem;
  for (std::size_t c = 0; c < corners.size(); ++c) {
    for (std::size_t k = 0; k < poses.size(); ++k) {
      const Eigen::Vector2d uv = ReferenceProjection(camera, poses[k], T_true, corners_true[c]);
      ASSERT_TRUE(camera.InImage(uv)) << c << " " << k;
      problem.AddResidualBlock(CornerReprojectionResidual::Create(camera, uv, 1.0), nullptr,
                               corners[c].data(), pose_blocks[k].q.data(), pose_blocks[k].t.data(),
                               extrinsic.q.data(), extrinsic.t.data());
    }
  }
  // The lever arm is not what this test recovers (one pass over flat ground barely observes
  // it): it is held at its true value, the rotation is free.
  problem.SetParameterBlockConstant(extrinsic.t.data());
  problem.SetManifold(extrinsic.q.data(), new ceres::EigenQuaternionManifold);
  for (PoseBlocks& pose : pose_blocks) {
    problem.SetParameterBlockConstant(pose.q.data());
    problem.SetParameterBlockConstant(pose.t.data());
  }

  ceres::Solver::Summary summary;
  ceres::Solve(TightSolverOptions(), &problem, &summary);
  std::cout << summary.BriefReport() << "\n";
  ASSERT_TRUE(summary.IsSolutionUsable());
  EXPECT_EQ(summary.termination_type, ceres::CONVERGENCE);

  const Eigen::Isometry3d T_est = FromBlocks(extrinsic);
  EXPECT_NEAR(ExtrinsicPitch(T_est.linear()) / kDeg, 5.0, 0.02);
  EXPECT_LT(RotationAngleBetween(T_est, T_true) / kDeg, 0.02);
  // (The translation is held constant above, so there is nothing to assert about it.)
  for (std::size_t c = 0; c < corners.size(); ++c) {
    EXPECT_LT((corners[c] - corners_true[c]).norm(), 0.02) << c;
  }
}

TEST(ResidualSolveTest, PpsrRecoversALaneSegment) {
  const PinholeCamera camera = TestCamera();
  const Eigen::Isometry3d T_base_cam = Extrinsic(5.0 * kDeg);
  const std::vector<Eigen::Isometry3d> poses = DrivePoses();
  const Eigen::Vector3d c1_true(18.0, 1.8, 0.0), c2_true(24.0, 2.2, 0.0);

  // Lane pixels on the projected segment line in every frame (inside and beyond it). The
  // points along the segment are unobservable from PPSR, so x is held (SubsetManifold):
  // what is estimated is the lateral position and height of both ends.
  Eigen::Vector3d c1 = c1_true + Eigen::Vector3d(0.0, 0.5, 0.3);
  Eigen::Vector3d c2 = c2_true + Eigen::Vector3d(0.0, -0.4, -0.2);
  std::vector<PoseBlocks> pose_blocks;
  for (const Eigen::Isometry3d& T : poses) pose_blocks.push_back(ToBlocks(T));
  PoseBlocks extrinsic = ToBlocks(T_base_cam);

  ceres::Problem problem;
  for (std::size_t k = 0; k < poses.size(); ++k) {
    const Eigen::Vector2d a = ReferenceProjection(camera, poses[k], T_base_cam, c1_true);
    const Eigen::Vector2d b = ReferenceProjection(camera, poses[k], T_base_cam, c2_true);
    for (double s : {-0.2, 0.1, 0.4, 0.7, 1.0}) {
      problem.AddResidualBlock(PpsrResidual::Create(camera, a + s * (b - a), 1.0),
                               new ceres::HuberLoss(2.0), c1.data(), c2.data(),
                               pose_blocks[k].q.data(), pose_blocks[k].t.data(), extrinsic.q.data(),
                               extrinsic.t.data());
    }
    problem.SetParameterBlockConstant(pose_blocks[k].q.data());
    problem.SetParameterBlockConstant(pose_blocks[k].t.data());
  }
  problem.SetParameterBlockConstant(extrinsic.q.data());
  problem.SetParameterBlockConstant(extrinsic.t.data());
  problem.SetManifold(c1.data(), new ceres::SubsetManifold(3, {0}));
  problem.SetManifold(c2.data(), new ceres::SubsetManifold(3, {0}));

  ceres::Solver::Summary summary;
  ceres::Solve(TightSolverOptions(), &problem, &summary);
  std::cout << summary.BriefReport() << "\n";
  ASSERT_TRUE(summary.IsSolutionUsable());
  EXPECT_EQ(summary.termination_type, ceres::CONVERGENCE);
  EXPECT_LT((c1 - c1_true).norm(), 1e-3);
  EXPECT_LT((c2 - c2_true).norm(), 1e-3);
}

TEST(ResidualSolveTest, PsrRecoversControlPoints) {
  // A curving lane of 6 control points (3 segments), sampled on the curve.
  std::vector<Eigen::Vector3d> control_true;
  for (int i = 0; i < 6; ++i) {
    const double x = 10.0 + 4.0 * i;
    control_true.emplace_back(x, 0.01 * x * x, 0.02 * i);
  }
  const CatmullRomSpline spline(control_true);
  std::vector<Eigen::Vector3d> control = control_true;
  for (int i = 0; i < 6; ++i) {
    control[i] += Eigen::Vector3d(0.3 * std::sin(1.7 * i), 0.5 * std::cos(2.3 * i), 0.1 * (i % 2));
  }

  ceres::Problem problem;
  for (int segment = 0; segment < spline.NumSegments(); ++segment) {
    for (double u : {0.0, 0.2, 0.4, 0.6, 0.8, 1.0}) {
      problem.AddResidualBlock(PsrResidual::Create(spline.Evaluate(segment + u), u, 0.1), nullptr,
                               control[segment].data(), control[segment + 1].data(),
                               control[segment + 2].data(), control[segment + 3].data());
    }
  }
  ceres::Solver::Summary summary;
  ceres::Solve(TightSolverOptions(), &problem, &summary);
  std::cout << summary.BriefReport() << "\n";
  ASSERT_TRUE(summary.IsSolutionUsable());
  for (int i = 0; i < 6; ++i) EXPECT_LT((control[i] - control_true[i]).norm(), 1e-6) << i;
}

TEST(ResidualSolveTest, PoseStepCorrectsOdometryWithMarkings) {
  // Pose step: poses free with their odometry priors, corners and extrinsic held. The
  // odometry is off by 0.4 m, 0.2 m and 0.5 deg yaw; the exact corner measurements pull the
  // pose back to the truth, the loose prior barely resists.
  const PinholeCamera camera = TestCamera();
  const Eigen::Isometry3d T_base_cam = Extrinsic(5.0 * kDeg);
  PoseBlocks extrinsic = ToBlocks(T_base_cam);
  const Eigen::Isometry3d T_true = VehiclePose();
  const Eigen::Isometry3d T_odom =
      T_true * ExpSe3((Vector6d() << 0.4, -0.2, 0.0, 0.0, 0.0, 0.5 * kDeg).finished());
  std::vector<Eigen::Vector3d> corners;
  for (double x : {9.0, 14.0, 22.0}) {
    for (double y : {-2.5, 2.0}) corners.push_back(T_true * Eigen::Vector3d(x, y, 0.0));
  }

  PoseBlocks pose = ToBlocks(T_odom);
  ceres::Problem problem;
  for (Eigen::Vector3d& corner : corners) {
    problem.AddResidualBlock(
        CornerReprojectionResidual::Create(
            camera, ReferenceProjection(camera, T_true, T_base_cam, corner), 1.0),
        new ceres::HuberLoss(3.0), corner.data(), pose.q.data(), pose.t.data(), extrinsic.q.data(),
        extrinsic.t.data());
    problem.SetParameterBlockConstant(corner.data());
  }
  problem.AddResidualBlock(PosePriorResidual::Create(T_odom, Eigen::Vector3d(1.0, 0.5, 0.1),
                                                     Eigen::Vector3d::Constant(2.0 * kDeg)),
                           nullptr, pose.q.data(), pose.t.data());
  problem.SetManifold(pose.q.data(), new ceres::EigenQuaternionManifold);
  problem.SetParameterBlockConstant(extrinsic.q.data());
  problem.SetParameterBlockConstant(extrinsic.t.data());

  ceres::Solver::Summary summary;
  ceres::Solve(TightSolverOptions(), &problem, &summary);
  std::cout << summary.BriefReport() << "\n";
  ASSERT_TRUE(summary.IsSolutionUsable());
  const Eigen::Isometry3d T_est = FromBlocks(pose);
  EXPECT_LT((T_est.translation() - T_true.translation()).norm(), 0.005);
  EXPECT_LT(RotationAngleBetween(T_est, T_true) / kDeg, 0.01);
}

}  // namespace
}  // namespace residuals
}  // namespace ipm_road_mapper
