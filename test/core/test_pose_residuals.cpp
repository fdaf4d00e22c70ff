// Tests of the Ceres prior residuals of the pose optimization (docs/design.md §4): the
// pose prior, the motion prior and the constant-twist prior; autodiff Jacobians against numeric
// differences (on the quaternion manifold) and values against independently computed formulas.
#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <vector>

#include "common/residual_scene.h"
#include "ipm_road_mapper/core/backend/residuals/constant_twist_prior_residual.h"
#include "ipm_road_mapper/core/backend/residuals/motion_prior_residual.h"
#include "ipm_road_mapper/core/backend/residuals/pose_prior_residual.h"

namespace ipm_road_mapper {
namespace residuals {
namespace {

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
// Constant-twist prior (the newest poses' tail, pose_extrapolator.h).

class ConstantTwistPriorTest : public ::testing::Test {
 protected:
  Eigen::VectorXd Residual(const std::array<PoseBlocks, 3>& p, double dt_a, double dt_b) const {
    std::unique_ptr<ceres::CostFunction> cost(
        ConstantTwistPriorResidual::Create(dt_a, dt_b, sigma_acc_, sigma_ang_));
    return Evaluate(*cost, {p[0].q.data(), p[0].t.data(), p[1].q.data(), p[1].t.data(),
                            p[2].q.data(), p[2].t.data()});
  }
  // Three poses on a circle of `radius` at `speed`, heading along it, `dt` apart, pitched a
  // little, starting at heading `yaw0`.
  static std::array<PoseBlocks, 3> OnArc(double radius, double speed, double dt, double yaw0) {
    std::array<PoseBlocks, 3> p;
    for (int i = 0; i < 3; ++i) {
      const double yaw = yaw0 + speed * dt * i / radius;
      Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
      T.linear() = RotationFromRpy(0.0, 1.5 * kDeg, yaw);
      T.translation() = Eigen::Vector3d(radius * std::sin(yaw), -radius * std::cos(yaw), 0.3);
      p[i] = ToBlocks(T);
    }
    return p;
  }
  const Eigen::Vector3d sigma_acc_ = Eigen::Vector3d(1.0, 2.0, 4.0);
  const Eigen::Vector3d sigma_ang_ = Eigen::Vector3d(0.5, 0.25, 0.125);
};

TEST_F(ConstantTwistPriorTest, IsZeroOnAConstantSpeedTurnWhereTheMapFramePriorIsNot) {
  // 10 m/s on a 200 m curve: the map-frame prior sees the centripetal 0.5 m/s^2.
  const std::array<PoseBlocks, 3> p = OnArc(200.0, 10.0, 0.05, 0.7);
  EXPECT_LT(Residual(p, 0.05, 0.05).norm(), 1e-9);
  std::unique_ptr<ceres::CostFunction> map_frame(
      MotionPriorResidual::Create(0.05, 0.05, sigma_acc_, sigma_ang_));
  const Eigen::VectorXd r_map = Evaluate(*map_frame, {p[0].q.data(), p[0].t.data(), p[1].q.data(),
                                                      p[1].t.data(), p[2].q.data(), p[2].t.data()});
  EXPECT_NEAR(r_map.head<3>().norm(), 0.5 / sigma_acc_(1), 0.01);
  std::array<PoseBlocks, 3> negated = p;
  negated[2] = Negated(negated[2]);  // the quaternion sign means nothing
  EXPECT_LT(Residual(negated, 0.05, 0.05).norm(), 1e-9);
}

TEST_F(ConstantTwistPriorTest, IsTheChangeOfSpeedInTheBodyFrameOverSigma) {
  // Heading 90 deg in the map (body x is map y): 10 m/s, then 10.09 m/s.
  const double dt_a = 0.05, dt_b = 0.04, dt = 0.5 * (dt_a + dt_b);
  const double ys[3] = {0.0, 10.0 * dt_a, 10.0 * dt_a + 10.09 * dt_b};
  std::array<PoseBlocks, 3> p;
  for (int i = 0; i < 3; ++i) p[i] = ToBlocks(test::PlanarPose(3.0, ys[i], M_PI / 2));
  const Eigen::VectorXd r = Residual(p, dt_a, dt_b);
  EXPECT_NEAR(r(0), 0.09 / (dt * sigma_acc_(0)), 1e-9);
  EXPECT_NEAR(r(1), 0.0, 1e-9);
  EXPECT_NEAR(r(2), 0.0, 1e-9);
  EXPECT_LT(r.tail<3>().norm(), 1e-9);
}

TEST_F(ConstantTwistPriorTest, IsTheChangeOfTurnRateOverSigma) {
  const double dt_a = 0.05, dt_b = 0.06, dt = 0.5 * (dt_a + dt_b);
  const double yaw[3] = {0.0, 0.1 * dt_a, 0.1 * dt_a + 0.2 * dt_b};
  std::array<PoseBlocks, 3> p;
  for (int i = 0; i < 3; ++i) p[i] = ToBlocks(test::PlanarPose(1.0, 2.0, yaw[i]));
  const Eigen::VectorXd r = Residual(p, dt_a, dt_b);
  EXPECT_LT(r.head<3>().norm(), 1e-9);
  EXPECT_NEAR(r(5), 0.1 / (dt * sigma_ang_(2)), 1e-9);
  EXPECT_NEAR(r(3), 0.0, 1e-9);
  EXPECT_NEAR(r(4), 0.0, 1e-9);
}

TEST_F(ConstantTwistPriorTest, GradientCheck) {
  std::unique_ptr<ceres::CostFunction> cost(
      ConstantTwistPriorResidual::Create(0.05, 0.06, sigma_acc_, sigma_ang_));
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

}  // namespace
}  // namespace residuals
}  // namespace ipm_road_mapper
