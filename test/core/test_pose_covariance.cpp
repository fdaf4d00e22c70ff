// Pose covariances (pose_covariance.h): the Ceres covariance of a pose held only by its
// odometry prior is that prior's covariance in map axes (which checks the block order and
// the axes), and carrying a covariance along the odometry matches perturbing the solved
// pose and re-propagating the correction.
#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include <random>

#include "ipm_road_mapper/core/backend/pose_covariance.h"
#include "ipm_road_mapper/core/backend/residuals/pose_prior_residual.h"
#include "ipm_road_mapper/core/geometry/rigid_transform.h"

namespace ipm_road_mapper {
namespace {

Eigen::Isometry3d Pose(double x, double y, double z, double roll, double pitch, double yaw) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = RotationFromRpy(roll, pitch, yaw);
  T.translation() = Eigen::Vector3d(x, y, z);
  return T;
}

TEST(PoseCovariance, OfAPoseHeldByItsPriorIsThePriorInMapAxes) {
  const Eigen::Isometry3d T_map_base = Pose(12.0, -3.0, 0.4, 0.02, -0.03, 0.9);
  const Eigen::Vector3d sigma_t(0.15, 0.05, 0.02), sigma_r(0.001, 0.002, 0.005);
  Eigen::Quaterniond q(T_map_base.linear());
  Eigen::Vector3d t = T_map_base.translation();
  ceres::Problem problem;
  problem.AddResidualBlock(residuals::PosePriorResidual::Create(T_map_base, sigma_t, sigma_r),
                           nullptr, q.coeffs().data(), t.data());
  problem.SetManifold(q.coeffs().data(), new ceres::EigenQuaternionManifold);
  PoseCovariance covariance;
  ASSERT_TRUE(ComputePoseCovariance(&problem, q.coeffs().data(), t.data(), &covariance));
  const PoseCovariance expected = OdometryPoseCovariance(T_map_base, sigma_t, sigma_r);
  EXPECT_LT((covariance - expected).cwiseAbs().maxCoeff(), 1e-6 * expected.diagonal().maxCoeff())
      << covariance << "\nexpected\n"
      << expected;
}

TEST(PoseCovariance, NotComputedForAConstantOrAbsentPose) {
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  ceres::Problem problem;
  PoseCovariance covariance;
  EXPECT_FALSE(ComputePoseCovariance(&problem, q.coeffs().data(), t.data(), &covariance));
  problem.AddResidualBlock(
      residuals::PosePriorResidual::Create(Eigen::Isometry3d::Identity(), Eigen::Vector3d::Ones(),
                                           Eigen::Vector3d::Ones()),
      nullptr, q.coeffs().data(), t.data());
  problem.SetParameterBlockConstant(t.data());
  EXPECT_FALSE(ComputePoseCovariance(&problem, q.coeffs().data(), t.data(), &covariance));
}

// Samples perturbations of the solved pose, re-propagates the correction to a pose 20 m
// further on and compares the sample covariance of the new pose's error with the formula.
TEST(PoseCovariance, CarriedAlongTheOdometryAsThePerturbedCorrection) {
  const Eigen::Isometry3d T_odom_opt = Pose(100.0, 5.0, 0.2, 0.0, 0.0, 0.3);
  const Eigen::Isometry3d T_odom_new = Pose(118.0, 13.0, 0.3, 0.0, 0.0, 0.5);
  const Eigen::Isometry3d C = Pose(0.2, -0.1, 0.0, 0.0, 0.0, 0.004);  // T_map_odom
  const Eigen::Isometry3d T_opt = C * T_odom_opt, T_new = C * T_odom_new;
  Eigen::Matrix<double, 6, 1> sigmas;
  sigmas << 0.05, 0.03, 0.01, 0.001, 0.001, 0.003;  // x y z, rot x y z (map axes)
  PoseCovariance covariance_opt = sigmas.cwiseAbs2().asDiagonal();
  covariance_opt(0, 5) = covariance_opt(5, 0) = 0.5 * sigmas(0) * sigmas(5);  // correlated
  const Eigen::Matrix<double, 6, 6> L = covariance_opt.llt().matrixL();
  std::mt19937 rng(7);
  std::normal_distribution<double> normal;
  PoseCovariance sample = PoseCovariance::Zero();
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    Eigen::Matrix<double, 6, 1> z;
    for (int j = 0; j < 6; ++j) z(j) = normal(rng);
    const Eigen::Matrix<double, 6, 1> d = L * z;
    Eigen::Isometry3d T = T_opt;  // t + dt, Exp(dtheta) R
    T.translation() += d.head<3>();
    T.linear() =
        Eigen::AngleAxisd(d.tail<3>().norm(), d.tail<3>().normalized()).toRotationMatrix() *
        T.linear();
    const Eigen::Isometry3d T_new_perturbed = (T * T_odom_opt.inverse()) * T_odom_new;
    Eigen::Matrix<double, 6, 1> e;
    e.head<3>() = T_new_perturbed.translation() - T_new.translation();
    const Eigen::AngleAxisd dR(T_new_perturbed.linear() * T_new.linear().transpose());
    e.tail<3>() = dR.angle() * dR.axis();
    sample += e * e.transpose() / n;
  }
  const PoseCovariance carried =
      PropagatePoseCovariance(covariance_opt, T_opt, T_new, PoseCovariance::Zero());
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 6; ++c) {
      const double scale = std::sqrt(carried(r, r) * carried(c, c));
      EXPECT_NEAR(sample(r, c), carried(r, c), 0.05 * scale) << r << ", " << c;
    }
  }
  // 20 m of lever arm: 0.003 rad of yaw becomes 6 cm across; the x-y block grows.
  EXPECT_GT(carried(1, 1), 2.0 * covariance_opt(1, 1));
  // The new frame's own odometry noise adds on top.
  const PoseCovariance odometry = OdometryPoseCovariance(T_new, Eigen::Vector3d(0.1, 0.1, 0.02),
                                                         Eigen::Vector3d(0.001, 0.001, 0.003));
  EXPECT_TRUE(PropagatePoseCovariance(covariance_opt, T_opt, T_new, odometry)
                  .isApprox(carried + odometry, 1e-12));
}

}  // namespace
}  // namespace ipm_road_mapper
