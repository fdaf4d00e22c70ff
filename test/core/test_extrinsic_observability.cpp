// Observability of the extrinsic (extrinsic_observability.h): the decomposition against the
// prior, the information of a Ceres problem (equal to the Schur complement that the
// marginalization computes in the same chart), and what a drive observes: a straight one
// not the x/y lever arm, a turning one does.
#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include <random>

#include "common/test_scene.h"
#include "ipm_road_mapper/core/backend/extrinsic_marginalization.h"
#include "ipm_road_mapper/core/backend/extrinsic_observability.h"
#include "ipm_road_mapper/core/backend/residuals/corner_reprojection_residual.h"
#include "ipm_road_mapper/core/backend/residuals/road_surface_prior_residual.h"

namespace ipm_road_mapper {
namespace {

constexpr double kDeg = M_PI / 180.0;

TEST(AnalyzeObservability, PitchAndHeightTogetherAreOneDirection) {
  // The data knows only one combination of pitch and height (the homography's), well.
  Vector6d u = Vector6d::Zero();
  u(1) = 1.0;  // pitch
  u(5) = 0.5;  // z
  const Matrix6d H = 1e6 * u * u.transpose();
  const ExtrinsicObservability o = AnalyzeObservability(H, Vector6d::Ones(), 4.0);
  EXPECT_EQ(o.rank, 1);
  EXPECT_TRUE(o.axis_observed[1]);   // pitch: 80 % of the observed direction
  EXPECT_FALSE(o.axis_observed[5]);  // z: 20 %
  EXPECT_FALSE(o.axis_observed[0]);
  EXPECT_EQ(ObservedAxesText(o.axis_observed), "pitch");
  // The observed information is all of H; the hold leaves exactly that direction free.
  EXPECT_LT((o.ObservedInformation() - H).norm(), 1e-6 * H.norm());
  const Matrix6d L = o.UnobservedHoldSqrtInformation(1.0);
  EXPECT_LT((L * u).norm(), 1e-9);
  Vector6d pitch_alone = Vector6d::Zero();
  pitch_alone(1) = 1.0;
  EXPECT_GT((L * pitch_alone).norm(), 0.4);  // pitch alone would spoil the homography
  // Below the ratio (1e-6 * 1.25 of the prior's information), nothing is observed.
  const ExtrinsicObservability weak = AnalyzeObservability(1e-6 * H, Vector6d::Ones(), 4.0);
  EXPECT_EQ(weak.rank, 0);
  EXPECT_EQ(ObservedAxesText(weak.axis_observed), "none");
}

TEST(AnalyzeObservability, RatioIsAgainstThePriorSigma) {
  // Information 100 m^-2 on x: 10 cm of data sigma. Against a 5 cm prior that is a ratio
  // of 0.25 (not observed), against a 1 m prior 100 (observed).
  Matrix6d H = Matrix6d::Zero();
  H(3, 3) = 100.0;
  Vector6d sigma = Vector6d::Constant(0.05);
  EXPECT_EQ(AnalyzeObservability(H, sigma, 4.0).rank, 0);
  sigma(3) = 1.0;
  const ExtrinsicObservability o = AnalyzeObservability(H, sigma, 4.0);
  EXPECT_EQ(o.rank, 1);
  EXPECT_TRUE(o.axis_observed[3]);
}

// Markings on the ground seen by a camera on a vehicle driving the given poses, 1 px noise.
struct Drive {
  PinholeCamera camera{test::Intrinsics1280x720()};
  Eigen::Isometry3d T_base_cam = test::MountedCamera(0.0, 4.0 * kDeg, 0.0);
  std::vector<Eigen::Isometry3d> poses;
  std::vector<Eigen::Vector3d> points;
  struct Obs {
    int point, pose;
    Eigen::Vector2d uv;
  };
  std::vector<Obs> observations;
  void Observe() {
    std::mt19937 rng(3);
    std::normal_distribution<double> noise(0.0, 1.0);
    for (std::size_t p = 0; p < points.size(); ++p) {
      for (std::size_t k = 0; k < poses.size(); ++k) {
        const Eigen::Vector3d p_cam = (poses[k] * T_base_cam).inverse() * points[p];
        Eigen::Vector2d uv;
        if (p_cam.z() < 3.0 || p_cam.z() > 30.0 || !camera.Project(p_cam, &uv) ||
            !camera.InImage(uv)) {
          continue;
        }
        observations.push_back({static_cast<int>(p), static_cast<int>(k),
                                uv + Eigen::Vector2d(noise(rng), noise(rng))});
      }
    }
  }
};

// Straight along x, points 10-40 m ahead on both sides.
Drive StraightDrive() {
  Drive d;
  for (int k = 0; k < 40; ++k) d.poses.push_back(test::PlanarPose(0.5 * k, 0.0, 0.0));
  for (int i = 0; i < 12; ++i) {
    d.points.emplace_back(10.0 + 2.5 * i, i % 2 ? 1.8 : -1.8, 0.0);
  }
  d.Observe();
  return d;
}

// Straight, a 75 deg turn (2.5 deg per 0.6 m), straight again: the curvature changes. (A
// turn of constant radius alone does not do: moving the camera forward and turning it by
// dx / radius rotates its whole path about the turn's center, a rigid motion the map
// follows.) Points 2 m either side of the path every 3 m.
Drive TurningDrive() {
  Drive d;
  Eigen::Vector2d position(0.0, 0.0);
  double yaw = 0.0;
  std::vector<std::pair<Eigen::Vector2d, double>> path;
  for (int k = 0; k < 110; ++k) {
    path.emplace_back(position, yaw);
    if (k >= 25 && k < 55) yaw += 2.5 * kDeg;
    position += 0.6 * Eigen::Vector2d(std::cos(yaw), std::sin(yaw));
  }
  for (int k = 0; k < 80; ++k) {
    d.poses.push_back(test::PlanarPose(path[k].first.x(), path[k].first.y(), path[k].second));
  }
  for (std::size_t k = 10; k < path.size(); k += 5) {
    const Eigen::Vector2d normal(-std::sin(path[k].second), std::cos(path[k].second));
    for (double side : {-2.0, 2.0}) {
      const Eigen::Vector2d p = path[k].first + side * normal;
      d.points.emplace_back(p.x(), p.y(), 0.0);
    }
  }
  d.Observe();
  return d;
}

struct Blocks {
  double q[4], t[3];
  explicit Blocks(const Eigen::Isometry3d& T) {
    Eigen::Map<Eigen::Quaterniond> q_map(q);
    q_map = Eigen::Quaterniond(T.linear());
    Eigen::Map<Eigen::Vector3d> t_map(t);
    t_map = T.translation();
  }
};

// The drive's problem (points free, 5 cm road prior each, the extrinsic free on the
// quaternion manifold) and its extrinsic information.
Matrix6d ProblemInformation(const Drive& d, std::vector<Eigen::Vector3d> points) {
  ceres::Problem problem;
  Blocks extrinsic(d.T_base_cam);
  std::vector<Blocks> poses;
  for (const auto& T : d.poses) poses.emplace_back(T);
  for (const Drive::Obs& o : d.observations) {
    problem.AddResidualBlock(residuals::CornerReprojectionMapStepResidual::Create(
                                 d.camera, o.uv, 1.0, poses[o.pose].q, poses[o.pose].t),
                             nullptr, points[o.point].data(), extrinsic.q, extrinsic.t);
  }
  for (auto& p : points) {
    if (!problem.HasParameterBlock(p.data())) continue;
    problem.AddResidualBlock(residuals::RoadSurfacePriorResidual::Create(RoadPlane(), 0.05),
                             nullptr, p.data());
  }
  problem.SetManifold(extrinsic.q, new ceres::EigenQuaternionManifold);
  return ExtrinsicInformation(&problem, extrinsic.q, extrinsic.t, {});
}

TEST(ExtrinsicInformation, EqualsTheMarginalizationsSchurComplement) {
  const Drive d = TurningDrive();
  const Matrix6d H = ProblemInformation(d, d.points);
  const ExtrinsicPrior chart(d.T_base_cam, Eigen::Vector3d::Constant(kDeg),
                             Eigen::Vector3d::Constant(0.05));
  MarginalizationInput input;
  input.points = d.points;
  for (const Drive::Obs& o : d.observations)
    input.corners.push_back({o.point, o.uv, d.poses[o.pose]});
  for (std::size_t p = 0; p < d.points.size(); ++p) {
    input.road_priors.push_back({static_cast<int>(p), RoadPlane(), 0.05});
  }
  const ExtrinsicFactor factor =
      MarginalizeIntoExtrinsic(d.camera, chart, d.T_base_cam, input, 1.0, 0.0);
  ASSERT_GT(factor.H.norm(), 0.0);
  EXPECT_LT((H - factor.H).norm(), 1e-4 * factor.H.norm()) << H << "\n\n" << factor.H;
}

TEST(ExtrinsicInformation, LeverArmObservedInTurnsOnly) {
  const Vector6d sigma =
      PriorSigma(Eigen::Vector3d::Constant(2.0 * kDeg), Eigen::Vector3d::Constant(0.05));
  const Drive straight = StraightDrive();
  const ExtrinsicObservability o_straight =
      AnalyzeObservability(ProblemInformation(straight, straight.points), sigma, 4.0);
  EXPECT_TRUE(o_straight.axis_observed[1]);   // pitch
  EXPECT_FALSE(o_straight.axis_observed[3]);  // x: a shift of the whole map
  EXPECT_FALSE(o_straight.axis_observed[4]);  // y
  const Drive turning = TurningDrive();
  const ExtrinsicObservability o_turning =
      AnalyzeObservability(ProblemInformation(turning, turning.points), sigma, 4.0);
  EXPECT_TRUE(o_turning.axis_observed[3]) << o_turning.eigenvalues.transpose();
  EXPECT_TRUE(o_turning.axis_observed[4]) << o_turning.eigenvalues.transpose();
}

TEST(ExtrinsicInformation, ZeroWhenTheExtrinsicIsHeld) {
  const Drive d = StraightDrive();
  ceres::Problem problem;
  Blocks extrinsic(d.T_base_cam);
  std::vector<Eigen::Vector3d> points = d.points;
  Blocks pose(d.poses[0]);
  const Drive::Obs& o = d.observations.front();
  problem.AddResidualBlock(
      residuals::CornerReprojectionMapStepResidual::Create(d.camera, o.uv, 1.0, pose.q, pose.t),
      nullptr, points[o.point].data(), extrinsic.q, extrinsic.t);
  problem.SetManifold(extrinsic.q, new ceres::EigenQuaternionManifold);
  problem.SetParameterBlockConstant(extrinsic.q);
  problem.SetParameterBlockConstant(extrinsic.t);
  EXPECT_EQ(ExtrinsicInformation(&problem, extrinsic.q, extrinsic.t, {}).norm(), 0.0);
}

}  // namespace
}  // namespace ipm_road_mapper
