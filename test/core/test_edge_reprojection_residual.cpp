// Tests of the marking edge reprojection residual (edge_reprojection_residual.h): autodiff
// Jacobians against Ridders' differences on the quaternion manifold, the value against the
// perpendicular pixel distance computed independently, the step bindings against the
// reference, and the cases a partial view brings (a corner behind the camera).
#include <ceres/ceres.h>
#include <ceres/gradient_checker.h>
#include <ceres/manifold.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <array>
#include <memory>
#include <vector>

#include "common/test_scene.h"
#include "ipm_road_mapper/core/backend/residuals/edge_reprojection_residual.h"
#include "ipm_road_mapper/core/geometry/rigid_transform.h"

namespace ipm_road_mapper {
namespace residuals {
namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr double kGradientPrecision = 1e-7;

struct Blocks {
  std::array<double, 4> q{};
  std::array<double, 3> t{};
  explicit Blocks(const Eigen::Isometry3d& T) {
    Eigen::Map<Eigen::Vector4d>(q.data()) = Eigen::Quaterniond(T.linear()).coeffs();
    Eigen::Map<Eigen::Vector3d>(t.data()) = T.translation();
  }
};

double Evaluate(const ceres::CostFunction& cost, const std::vector<const double*>& parameters) {
  double residual = 0.0;
  EXPECT_TRUE(cost.Evaluate(parameters.data(), &residual, nullptr));
  return residual;
}

void ExpectJacobiansMatch(const ceres::CostFunction& cost,
                          const std::vector<const ceres::Manifold*>& manifolds,
                          const std::vector<const double*>& parameters) {
  ceres::NumericDiffOptions options;
  options.ridders_relative_initial_step_size = 1e-3;  // as test_residuals.cpp: 20-40 m values
  const ceres::GradientChecker checker(&cost, &manifolds, options);
  ceres::GradientChecker::ProbeResults results;
  EXPECT_TRUE(checker.Probe(parameters.data(), kGradientPrecision, &results)) << results.error_log;
  double largest_entry = 0.0;
  for (const auto& jacobian : results.local_jacobians) {
    largest_entry = std::max(largest_entry, jacobian.cwiseAbs().maxCoeff());
  }
  EXPECT_GT(largest_entry, 1e-3);  // a check of all-zero Jacobians proves nothing
}

const ceres::EigenQuaternionManifold kQuaternion;

// A vehicle pose with yaw, roll and pitch, so that no axis is special.
Eigen::Isometry3d VehiclePose() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = RotationFromRpy(1.0 * kDeg, -2.0 * kDeg, 35.0 * kDeg);
  T.translation() = Eigen::Vector3d(12.0, -4.0, 0.4);
  return T;
}

class EdgeReprojectionTest : public ::testing::Test {
 protected:
  Eigen::Vector3d Ground(double x_ahead, double y_left) const {
    return T_map_base_ * Eigen::Vector3d(x_ahead, y_left, 0.0);
  }
  // Pixel of a map point through `camera`.
  Eigen::Vector2d Project(const PinholeCamera& camera, const Eigen::Vector3d& p_map) const {
    Eigen::Vector2d uv;
    EXPECT_TRUE(camera.Project(
        Eigen::Vector3d((T_base_cam_.inverse() * T_map_base_.inverse()) * p_map), &uv));
    return uv;
  }
  std::vector<const double*> All(const Eigen::Vector3d& c1, const Eigen::Vector3d& c2) const {
    return {c1.data(),      c2.data(),           pose_.q.data(),
            pose_.t.data(), extrinsic_.q.data(), extrinsic_.t.data()};
  }

  // A camera 1.5 m up and ahead, pitched down 5 deg; mildly distorted, and a pinhole.
  const PinholeCamera camera_{test::Intrinsics1280x720(640.0, 360.0, test::kMildDistortion)};
  const PinholeCamera pinhole_{test::Intrinsics1280x720(640.0, 360.0)};
  const Eigen::Isometry3d T_base_cam_ = test::MountedCamera(0.0, 5.0 * kDeg, 0.0);
  const Eigen::Isometry3d T_map_base_ = VehiclePose();
  // The near side of a crossing 8-9 m ahead, 23 m long, a little slanted (no symmetry): both
  // ends far outside the image.
  Eigen::Vector3d c1_ = Ground(8.0, -12.0);
  Eigen::Vector3d c2_ = Ground(9.0, 11.0);
  Blocks pose_{T_map_base_};
  Blocks extrinsic_{T_base_cam_};
};

TEST_F(EdgeReprojectionTest, IsZeroForEveryPixelOfTheSidesLine) {
  // Points of the side in the view (distorted camera), and for the pinhole also points of its
  // line beyond the corners, far outside the image.
  for (double s : {0.4, 0.5, 0.6}) {
    const Eigen::Vector2d uv = Project(camera_, c1_ + s * (c2_ - c1_));
    std::unique_ptr<ceres::CostFunction> cost(EdgeReprojectionResidual::Create(camera_, uv, 2.0));
    EXPECT_NEAR(Evaluate(*cost, All(c1_, c2_)), 0.0, 1e-9) << "s " << s;
  }
  for (double s : {-0.2, 0.5, 1.3}) {
    const Eigen::Vector2d uv = Project(pinhole_, c1_ + s * (c2_ - c1_));
    std::unique_ptr<ceres::CostFunction> cost(EdgeReprojectionResidual::Create(pinhole_, uv, 2.0));
    EXPECT_NEAR(Evaluate(*cost, All(c1_, c2_)), 0.0, 1e-9) << "s " << s;
  }
}

TEST_F(EdgeReprojectionTest, IsThePerpendicularPixelDistanceOverSigma) {
  // Pinhole: the side's image is the line through two projected points of it.
  const Eigen::Vector2d a = Project(pinhole_, c1_ + 0.45 * (c2_ - c1_));
  const Eigen::Vector2d b = Project(pinhole_, c1_ + 0.55 * (c2_ - c1_));
  const Eigen::Vector2d d = (b - a).normalized();
  const Eigen::Vector2d normal(-d.y(), d.x());
  for (double offset_px : {-6.0, 3.0, 10.0}) {
    const Eigen::Vector2d uv = 0.5 * (a + b) + offset_px * normal + 17.0 * d;
    std::unique_ptr<ceres::CostFunction> cost(EdgeReprojectionResidual::Create(pinhole_, uv, 2.0));
    EXPECT_NEAR(std::abs(Evaluate(*cost, All(c1_, c2_))), std::abs(offset_px) / 2.0, 1e-9);
  }
}

TEST_F(EdgeReprojectionTest, GradientCheck) {
  const std::vector<const ceres::Manifold*> manifolds = {nullptr, nullptr,      &kQuaternion,
                                                         nullptr, &kQuaternion, nullptr};
  const Eigen::Vector2d on_side = Project(camera_, c1_ + 0.5 * (c2_ - c1_));
  for (const Eigen::Vector2d& offset : {Eigen::Vector2d(0.0, 4.0), Eigen::Vector2d(30.0, -3.0)}) {
    std::unique_ptr<ceres::CostFunction> cost(
        EdgeReprojectionResidual::Create(camera_, on_side + offset, 1.5));
    ExpectJacobiansMatch(*cost, manifolds, All(c1_, c2_));
  }
}

TEST_F(EdgeReprojectionTest, StepBindingsMatchTheReferenceAndPassGradientChecks) {
  const Eigen::Vector2d uv = Project(camera_, c1_ + 0.52 * (c2_ - c1_)) + Eigen::Vector2d(2.0, 5.0);
  std::unique_ptr<ceres::CostFunction> reference(
      EdgeReprojectionResidual::Create(camera_, uv, 1.5));
  const double expected = Evaluate(*reference, All(c1_, c2_));
  ASSERT_GT(std::abs(expected), 0.5);
  std::unique_ptr<ceres::CostFunction> map_step(
      EdgeReprojectionMapStepResidual::Create(camera_, uv, 1.5, pose_.q.data(), pose_.t.data()));
  const std::vector<const double*> map_blocks = {c1_.data(), c2_.data(), extrinsic_.q.data(),
                                                 extrinsic_.t.data()};
  EXPECT_NEAR(Evaluate(*map_step, map_blocks), expected, 1e-12);
  ExpectJacobiansMatch(*map_step, {nullptr, nullptr, &kQuaternion, nullptr}, map_blocks);
  std::unique_ptr<ceres::CostFunction> pose_step(EdgeReprojectionPoseStepResidual::Create(
      camera_, uv, 1.5, c1_, c2_, extrinsic_.q.data(), extrinsic_.t.data()));
  const std::vector<const double*> pose_blocks = {pose_.q.data(), pose_.t.data()};
  EXPECT_NEAR(Evaluate(*pose_step, pose_blocks), expected, 1e-12);
  ExpectJacobiansMatch(*pose_step, {&kQuaternion, nullptr}, pose_blocks);
}

TEST_F(EdgeReprojectionTest, WorksWithACornerBehindTheCamera) {
  // A side from behind the vehicle to 10 m ahead (a crossing driven over): the residual is
  // still the distance to the image of the side's line.
  const Eigen::Vector3d behind = Ground(-3.0, 2.0), ahead = Ground(10.0, 2.0);
  const Eigen::Vector2d uv = Project(camera_, behind + 0.9 * (ahead - behind));
  std::unique_ptr<ceres::CostFunction> cost(EdgeReprojectionResidual::Create(camera_, uv, 2.0));
  EXPECT_NEAR(Evaluate(*cost, All(behind, ahead)), 0.0, 1e-9);
  std::unique_ptr<ceres::CostFunction> off(
      EdgeReprojectionResidual::Create(camera_, uv + Eigen::Vector2d(8.0, 0.0), 2.0));
  EXPECT_GT(std::abs(Evaluate(*off, All(behind, ahead))), 1.0);
}

TEST_F(EdgeReprojectionTest, FailsForASideThroughTheCameraCenter) {
  const Eigen::Vector3d center = T_map_base_ * T_base_cam_.translation();
  const Eigen::Vector3d ray = (Ground(10.0, 0.0) - center).normalized();
  const Eigen::Vector3d a = center + 5.0 * ray, b = center + 9.0 * ray;
  std::unique_ptr<ceres::CostFunction> cost(
      EdgeReprojectionResidual::Create(camera_, Eigen::Vector2d(640.0, 500.0), 2.0));
  double residual = 0.0;
  const std::vector<const double*> blocks = All(a, b);
  EXPECT_FALSE(cost->Evaluate(blocks.data(), &residual, nullptr));
}

}  // namespace
}  // namespace residuals
}  // namespace ipm_road_mapper
