// Tests of the IPM uncertainty Omega_p: the autodiffed Jacobians against central differences
// of the IPM function and against independent closed forms (so a perturbation defined with
// the wrong sign or axis cannot pass by being consistent with itself), the assembly of
// Omega_p, its score, and point selection.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>
#include <ostream>
#include <string>
#include <vector>

#include "common/test_scene.h"
#include "ipm_road_mapper/core/geometry/ipm.h"
#include "ipm_road_mapper/core/geometry/ipm_uncertainty.h"
#include "ipm_road_mapper/core/geometry/rigid_transform.h"

namespace ipm_road_mapper {
namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr double kCameraHeight = 1.5;

// The test camera 1.2 m ahead, 0.1 m left and kCameraHeight up, turned by roll, pitch, yaw.
Eigen::Isometry3d MakeTBaseCam(double roll, double pitch, double yaw) {
  return test::MountedCamera(roll, pitch, yaw, Eigen::Vector3d(1.2, 0.1, kCameraHeight));
}

struct Setup {
  std::string name;
  bool distorted;
  double roll, pitch, yaw;
};

void PrintTo(const Setup& s, std::ostream* os) { *os << s.name; }

// Pixels below the horizon, spread over the lower image (near and far, left and right).
std::vector<Eigen::Vector2d> TestPixels() {
  return {{652.3, 700.0}, {652.3, 450.0}, {100.0, 650.0}, {1200.0, 600.0},
          {400.0, 380.0}, {900.0, 420.0}, {20.0, 710.0},  {1260.0, 500.0}};
}

// Central differences of PerturbedGroundPoint in (u, v, theta, h).
struct NumericJacobians {
  Eigen::Matrix<double, 3, 2> J_uv;
  Eigen::Vector3d J_theta, J_h;
};

NumericJacobians CentralDifferences(const PinholeCamera& camera, const Eigen::Isometry3d& T,
                                    const Eigen::Vector2d& uv) {
  auto f = [&](const Eigen::Vector2d& uv_, double theta, double h) {
    Eigen::Vector3d p;
    EXPECT_TRUE(PerturbedGroundPoint(camera, T, uv_, theta, h, &p));
    return p;
  };
  NumericJacobians J;
  const double du = 1e-3;  // px
  J.J_uv.col(0) =
      (f(uv + Eigen::Vector2d(du, 0), 0, 0) - f(uv - Eigen::Vector2d(du, 0), 0, 0)) / (2 * du);
  J.J_uv.col(1) =
      (f(uv + Eigen::Vector2d(0, du), 0, 0) - f(uv - Eigen::Vector2d(0, du), 0, 0)) / (2 * du);
  const double dtheta = 1e-6;  // rad
  J.J_theta = (f(uv, dtheta, 0) - f(uv, -dtheta, 0)) / (2 * dtheta);
  const double dh = 1e-5;  // m
  J.J_h = (f(uv, 0, dh) - f(uv, 0, -dh)) / (2 * dh);
  return J;
}

class IpmUncertaintyTest : public ::testing::TestWithParam<Setup> {
 protected:
  PinholeCamera camera() const {
    return PinholeCamera(test::AsymmetricIntrinsics(GetParam().distorted));
  }
  Eigen::Isometry3d T_base_cam() const {
    return MakeTBaseCam(GetParam().roll, GetParam().pitch, GetParam().yaw);
  }
};

TEST_P(IpmUncertaintyTest, GroundPointIsTheIpmOfThePixel) {
  const Ipm ipm(camera(), T_base_cam(), 1e6);
  for (const Eigen::Vector2d& uv : TestPixels()) {
    Eigen::Vector3d p_ipm, p_perturbed;
    ASSERT_EQ(ipm.PixelToGround(uv, &p_ipm), IpmStatus::kOk) << uv.transpose();
    ASSERT_TRUE(PerturbedGroundPoint(camera(), T_base_cam(), uv, 0.0, 0.0, &p_perturbed));
    EXPECT_LT((p_perturbed - p_ipm).norm(), 1e-12);
    const auto u = ComputeIpmUncertainty(camera(), T_base_cam(), uv, IpmErrorModel());
    ASSERT_TRUE(u.has_value());
    EXPECT_LT((u->p_base - p_ipm).norm(), 1e-12);
  }
}

TEST_P(IpmUncertaintyTest, AutodiffJacobiansMatchCentralDifferences) {
  for (const Eigen::Vector2d& uv : TestPixels()) {
    const auto u = ComputeIpmUncertainty(camera(), T_base_cam(), uv, IpmErrorModel());
    ASSERT_TRUE(u.has_value()) << uv.transpose();
    const NumericJacobians J = CentralDifferences(camera(), T_base_cam(), uv);
    EXPECT_LT((u->J_uv - J.J_uv).norm(), 1e-6 * J.J_uv.norm())
        << "uv " << uv.transpose() << "\nautodiff\n"
        << u->J_uv << "\nnumeric\n"
        << J.J_uv;
    EXPECT_LT((u->J_theta - J.J_theta).norm(), 1e-6 * J.J_theta.norm())
        << "uv " << uv.transpose() << "\nautodiff " << u->J_theta.transpose() << "\nnumeric "
        << J.J_theta.transpose();
    EXPECT_LT((u->J_h - J.J_h).norm(), 1e-6 * J.J_h.norm())
        << "uv " << uv.transpose() << "\nautodiff " << u->J_h.transpose() << "\nnumeric "
        << J.J_h.transpose();
  }
}

// Closed forms independent of the implementation: with c the camera centre, d the ray and
// p = c - c_z / d_z * d,
//  - raising the camera scales the ground offset: dp/dh = (p - c)_xy / c_z, dz = 0;
//  - pitching about base_link y turns the ray: dd/dtheta = e_y x d, so
//    dp/dtheta = lambda * (dd - dd_z / d_z * d) with lambda = -c_z / d_z;
//  - J_uv (x, y rows) is the inverse of the projection's Jacobian restricted to the ground.
TEST_P(IpmUncertaintyTest, JacobiansMatchIndependentClosedForms) {
  const Ipm ipm(camera(), T_base_cam(), 1e6);
  const Eigen::Vector3d c = T_base_cam().translation();
  for (const Eigen::Vector2d& uv : TestPixels()) {
    const auto u = ComputeIpmUncertainty(camera(), T_base_cam(), uv, IpmErrorModel());
    ASSERT_TRUE(u.has_value());
    const Eigen::Vector3d p = u->p_base;

    Eigen::Vector3d J_h_expected = (p - c) / c.z();
    J_h_expected.z() = 0.0;
    EXPECT_LT((u->J_h - J_h_expected).norm(), 1e-9 * J_h_expected.norm()) << uv.transpose();

    const Eigen::Vector3d d = p - c;  // any scale of the ray
    const Eigen::Vector3d dd = Eigen::Vector3d::UnitY().cross(d);
    const double lambda = 1.0;  // p = c + 1 * d for this scale
    const Eigen::Vector3d J_theta_expected = lambda * (dd - dd.z() / d.z() * d);
    EXPECT_LT((u->J_theta - J_theta_expected).norm(), 1e-9 * J_theta_expected.norm())
        << uv.transpose() << "\n"
        << u->J_theta.transpose() << "\n"
        << J_theta_expected.transpose();

    Eigen::Matrix2d J_project;  // d uv / d (x, y) on the ground
    for (int k = 0; k < 2; ++k) {
      Eigen::Vector3d delta = Eigen::Vector3d::Zero();
      delta(k) = 1e-4;
      Eigen::Vector2d plus, minus;
      ASSERT_TRUE(ipm.BaseToPixel(p + delta, &plus));
      ASSERT_TRUE(ipm.BaseToPixel(p - delta, &minus));
      J_project.col(k) = (plus - minus) / 2e-4;
    }
    const Eigen::Matrix2d J_uv_expected = J_project.inverse();
    EXPECT_LT((u->J_uv.topRows<2>() - J_uv_expected).norm(), 1e-5 * J_uv_expected.norm())
        << uv.transpose() << "\n"
        << u->J_uv << "\n"
        << J_uv_expected;
    EXPECT_NEAR(u->J_uv.row(2).norm(), 0.0, 1e-12);
  }
}

// Signs a robotics engineer can check by eye (REP-103: positive pitch is nose down).
TEST_P(IpmUncertaintyTest, JacobianSignsForAPixelStraightAhead) {
  const auto u = ComputeIpmUncertainty(camera(), T_base_cam(), {652.3, 500.0}, IpmErrorModel());
  ASSERT_TRUE(u.has_value());
  EXPECT_LT(u->J_theta.x(), 0.0) << "pitching down brings the ground point closer";
  EXPECT_GT(u->J_h.x(), 0.0) << "raising the camera pushes the ground point away";
  EXPECT_LT(u->J_uv(0, 1), 0.0) << "a lower pixel (larger v) is closer";
  EXPECT_LT(u->J_uv(1, 0), 0.0) << "a pixel more to the right (larger u) is more to the right";
}

TEST_P(IpmUncertaintyTest, OmegaIsTheFormulaAssembledFromNumericJacobians) {
  IpmErrorModel model;
  model.pixel_error_px = {1.5, 3.0};  // unequal, so swapping u and v shows
  model.pitch_sigma_rad = 0.4 * kDeg;
  model.height_sigma_m = 0.07;
  for (const Eigen::Vector2d& uv : TestPixels()) {
    const auto u = ComputeIpmUncertainty(camera(), T_base_cam(), uv, model);
    ASSERT_TRUE(u.has_value());
    const NumericJacobians J = CentralDifferences(camera(), T_base_cam(), uv);
    const Eigen::Vector3d e = J.J_uv * model.pixel_error_px;  // e_p is a vector (the paper)
    const Eigen::Matrix3d omega_expected =
        e * e.transpose() + std::pow(model.pitch_sigma_rad, 2) * J.J_theta * J.J_theta.transpose() +
        std::pow(model.height_sigma_m, 2) * J.J_h * J.J_h.transpose();
    EXPECT_LT((u->omega - omega_expected).norm(), 1e-5 * omega_expected.norm())
        << "uv " << uv.transpose() << "\n"
        << u->omega << "\nexpected\n"
        << omega_expected;
    EXPECT_NEAR(u->score, u->omega.trace(), 1e-12 * u->score);
    EXPECT_NEAR(u->score, omega_expected.trace(), 1e-5 * u->score);
    EXPECT_TRUE(u->omega.isApprox(u->omega.transpose(), 1e-14));
  }
}

TEST_P(IpmUncertaintyTest, ScoreGrowsWithDistanceAhead) {
  double previous_score = 0.0, previous_x = 0.0;
  int steps = 0;
  // Up the centre column from the bottom of the image towards the horizon.
  for (double v = 715.0; v > 300.0; v -= 15.0) {
    const auto u = ComputeIpmUncertainty(camera(), T_base_cam(), {652.3, v}, IpmErrorModel());
    if (!u) break;
    if (steps > 0) {
      EXPECT_GT(u->p_base.x(), previous_x) << "v " << v;
      EXPECT_GT(u->score, previous_score) << "v " << v << " x " << u->p_base.x();
    }
    previous_score = u->score;
    previous_x = u->p_base.x();
    ++steps;
  }
  EXPECT_GT(steps, 10);
  const auto near = ComputeIpmUncertainty(camera(), T_base_cam(), {652.3, 700.0}, {});
  const auto far = ComputeIpmUncertainty(camera(), T_base_cam(), {652.3, 400.0}, {});
  ASSERT_TRUE(near && far);
  EXPECT_GT(far->score, 10.0 * near->score);
}

TEST_P(IpmUncertaintyTest, ZeroErrorModelGivesZeroOmega) {
  IpmErrorModel zero;
  zero.pixel_error_px.setZero();
  zero.pitch_sigma_rad = 0.0;
  zero.height_sigma_m = 0.0;
  const auto u = ComputeIpmUncertainty(camera(), T_base_cam(), {700.0, 600.0}, zero);
  ASSERT_TRUE(u.has_value());
  EXPECT_EQ(u->omega, Eigen::Matrix3d::Zero());
  EXPECT_EQ(u->score, 0.0);
  EXPECT_GT(u->J_uv.norm(), 0.0);  // the Jacobians are still there
}

TEST_P(IpmUncertaintyTest, EachErrorSourceContributesItsOwnTerm) {
  const Eigen::Vector2d uv(800.0, 550.0);
  IpmErrorModel pixel_only;
  pixel_only.pitch_sigma_rad = 0.0;
  pixel_only.height_sigma_m = 0.0;
  IpmErrorModel pitch_only = pixel_only;
  pitch_only.pixel_error_px.setZero();
  pitch_only.pitch_sigma_rad = 0.3 * kDeg;
  IpmErrorModel height_only = pixel_only;
  height_only.pixel_error_px.setZero();
  height_only.height_sigma_m = 0.05;
  const auto all = ComputeIpmUncertainty(camera(), T_base_cam(), uv, IpmErrorModel());
  const auto a = ComputeIpmUncertainty(camera(), T_base_cam(), uv, pixel_only);
  const auto b = ComputeIpmUncertainty(camera(), T_base_cam(), uv, pitch_only);
  const auto c = ComputeIpmUncertainty(camera(), T_base_cam(), uv, height_only);
  ASSERT_TRUE(all && a && b && c);
  EXPECT_TRUE(all->omega.isApprox(a->omega + b->omega + c->omega, 1e-12));
  // Each term is rank one (a vector error, not a per-axis diagonal).
  for (const auto* term : {&*a, &*b, &*c}) {
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(term->omega);
    EXPECT_GT(eig.eigenvalues()(2), 0.0);
    EXPECT_LT(std::abs(eig.eigenvalues()(1)), 1e-12 * eig.eigenvalues()(2));
  }
}

TEST_P(IpmUncertaintyTest, PixelAboveHorizonHasNoUncertainty) {
  for (const Eigen::Vector2d& uv : {Eigen::Vector2d(652.3, 0.0), Eigen::Vector2d(10.0, 100.0),
                                    Eigen::Vector2d(1270.0, 150.0)}) {
    EXPECT_FALSE(ComputeIpmUncertainty(camera(), T_base_cam(), uv, IpmErrorModel()).has_value())
        << uv.transpose();
    Eigen::Vector3d p;
    EXPECT_FALSE(PerturbedGroundPoint(camera(), T_base_cam(), uv, 0.0, 0.0, &p));
  }
}

INSTANTIATE_TEST_SUITE_P(
    Cameras, IpmUncertaintyTest,
    ::testing::Values(Setup{"Pitched", false, 0.0, 4.0 * kDeg, 0.0},
                      Setup{"RollYawDistorted", true, -1.5 * kDeg, 5.0 * kDeg, 4.0 * kDeg}),
    [](const ::testing::TestParamInfo<Setup>& info) { return info.param.name; });

TEST(IpmErrorModel, DefaultsAreTheDesignValues) {
  const IpmErrorModel model;
  EXPECT_EQ(model.pixel_error_px, Eigen::Vector2d(2.0, 2.0));
  EXPECT_NEAR(model.pitch_sigma_rad, 0.3 * kDeg, 1e-15);
  EXPECT_EQ(model.height_sigma_m, 0.05);
}

// ---------------------------------------------------------------------------------------
// Point selection
// ---------------------------------------------------------------------------------------

using Indices = std::vector<std::size_t>;

TEST(SelectLowestScores, PicksTheNLowestAscending) {
  const std::vector<double> scores = {0.5, 0.1, 0.9, 0.3, 0.2, 0.7};
  EXPECT_EQ(SelectLowestScores(scores, 3), (Indices{1, 4, 3}));
  EXPECT_EQ(SelectLowestScores(scores, 1), (Indices{1}));
  EXPECT_EQ(SelectLowestScores(scores, 0), Indices{});
}

TEST(SelectLowestScores, AllIndicesWhenNExceedsSize) {
  const std::vector<double> scores = {0.5, 0.1, 0.9};
  EXPECT_EQ(SelectLowestScores(scores, 3), (Indices{1, 0, 2}));
  EXPECT_EQ(SelectLowestScores(scores, 10), (Indices{1, 0, 2}));
  EXPECT_EQ(SelectLowestScores({}, 5), Indices{});
}

TEST(SelectLowestScores, SkipsNonFiniteScores) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<double> scores = {nan, 0.4, inf, 0.2, nan, 0.3};
  EXPECT_EQ(SelectLowestScores(scores, 2), (Indices{3, 5}));
  EXPECT_EQ(SelectLowestScores(scores, 10), (Indices{3, 5, 1}));
  EXPECT_EQ(SelectLowestScores({nan, nan}, 2), Indices{});
}

TEST(SelectLowestScores, TiesKeepInputOrder) {
  const std::vector<double> scores = {0.3, 0.1, 0.3, 0.1, 0.3, 0.1};
  EXPECT_EQ(SelectLowestScores(scores, 4), (Indices{1, 3, 5, 0}));
  EXPECT_EQ(SelectLowestScores(scores, 6), (Indices{1, 3, 5, 0, 2, 4}));

  // Many ties (an unstable sort reorders them on inputs this long).
  std::vector<double> many(300);
  for (std::size_t i = 0; i < many.size(); ++i) many[i] = static_cast<double>((i * 7) % 3);
  const Indices selected = SelectLowestScores(many, 250);
  ASSERT_EQ(selected.size(), 250u);
  for (std::size_t k = 1; k < selected.size(); ++k) {
    const double a = many[selected[k - 1]], b = many[selected[k]];
    EXPECT_TRUE(a < b || (a == b && selected[k - 1] < selected[k])) << "position " << k;
  }
}

}  // namespace
}  // namespace ipm_road_mapper
