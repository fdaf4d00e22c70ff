// The extrinsic prior and the marginalization of retired points into it: marginalizing one
// half of a problem and solving the other half with that prior gives the joint solution
// (to first order), the chart round-trips, and the prior residual is the prior's cost.
#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include <random>

#include "common/test_scene.h"
#include "ipm_road_mapper/core/backend/extrinsic_marginalization.h"
#include "ipm_road_mapper/core/backend/extrinsic_prior.h"
#include "ipm_road_mapper/core/backend/residuals/corner_reprojection_residual.h"
#include "ipm_road_mapper/core/backend/residuals/extrinsic_prior_residual.h"
#include "ipm_road_mapper/core/backend/residuals/road_surface_prior_residual.h"
#include "ipm_road_mapper/core/geometry/rigid_transform.h"

namespace ipm_road_mapper {
namespace {

constexpr double kDeg = M_PI / 180.0;

// The test camera 1.5 m ahead and z up, pitched and rolled by the given degrees.
Eigen::Isometry3d Extrinsic(double pitch_deg, double roll_deg, double z) {
  return test::MountedCamera(roll_deg * kDeg, pitch_deg * kDeg, 0.0, Eigen::Vector3d(1.5, 0.0, z));
}

// Markings (4 corners each, on the ground) seen from a vehicle driving along x on a gentle
// curve, with 1 px noise; the rough extrinsic is 0.3 deg / 3 cm off.
struct Scene {
  PinholeCamera camera{test::Intrinsics1280x720(639.5, 359.5, test::kMildDistortion)};
  Eigen::Isometry3d T_true = Extrinsic(4.0, 0.0, 1.5);
  Eigen::Isometry3d T_rough = Extrinsic(4.3, 0.2, 1.47);
  std::vector<Eigen::Isometry3d> poses;
  std::vector<std::array<Eigen::Vector3d, 4>> markings;
  struct Obs {
    int marking, corner, pose;
    Eigen::Vector2d uv;
  };
  std::vector<Obs> observations;
  Scene() {
    std::mt19937 rng(5);
    std::normal_distribution<double> noise(0.0, 1.0);
    for (int k = 0; k < 60; ++k) {
      poses.push_back(test::PlanarPose(0.5 * k, 0.01 * k * k, 0.002 * k));
    }
    for (int m = 0; m < 6; ++m) {
      const double x = 12.0 + 4.0 * m, y = (m % 3 - 1) * 2.5;
      markings.push_back({Eigen::Vector3d(x, y - 0.3, 0), Eigen::Vector3d(x + 2, y - 0.3, 0),
                          Eigen::Vector3d(x + 2, y + 0.3, 0), Eigen::Vector3d(x, y + 0.3, 0)});
    }
    for (int m = 0; m < 6; ++m) {
      for (int k = 0; k < 60; ++k) {
        for (int c = 0; c < 4; ++c) {
          const Eigen::Vector3d p_cam = (poses[k] * T_true).inverse() * markings[m][c];
          Eigen::Vector2d uv;
          if (p_cam.z() < 4.0 || p_cam.z() > 25.0 || !camera.Project(p_cam, &uv) ||
              !camera.InImage(uv)) {
            continue;
          }
          observations.push_back({m, c, k, uv + Eigen::Vector2d(noise(rng), noise(rng))});
        }
      }
    }
  }
};

struct PoseBlock {
  double q[4], t[3];
};
PoseBlock Blocks(const Eigen::Isometry3d& T) {
  PoseBlock b;
  Eigen::Map<Eigen::Quaterniond> q(b.q);
  q = Eigen::Quaterniond(T.linear());
  Eigen::Map<Eigen::Vector3d> t(b.t);
  t = T.translation();
  return b;
}

// Joint least squares of the given markings' corners and the extrinsic, with `prior` on
// the extrinsic and a 5 cm road prior on each corner. Returns the extrinsic, and the corners
// in *corners (initialized from the truth plus 0.3 m).
Eigen::Isometry3d SolveJoint(const Scene& scene, const std::vector<int>& marking_ids,
                             const ExtrinsicPrior& prior,
                             std::vector<std::array<Eigen::Vector3d, 4>>* corners) {
  ceres::Problem problem;
  PoseBlock extrinsic = Blocks(scene.T_rough);
  std::vector<PoseBlock> poses;
  for (const auto& T : scene.poses) poses.push_back(Blocks(T));
  corners->assign(scene.markings.size(), {});
  for (int m : marking_ids) {
    for (int c = 0; c < 4; ++c)
      (*corners)[m][c] = scene.markings[m][c] + Eigen::Vector3d(0.3, -0.1, 0.0);
  }
  for (const Scene::Obs& o : scene.observations) {
    if (std::find(marking_ids.begin(), marking_ids.end(), o.marking) == marking_ids.end()) continue;
    problem.AddResidualBlock(residuals::CornerReprojectionMapStepResidual::Create(
                                 scene.camera, o.uv, 1.0, poses[o.pose].q, poses[o.pose].t),
                             nullptr, (*corners)[o.marking][o.corner].data(), extrinsic.q,
                             extrinsic.t);
  }
  for (int m : marking_ids) {
    for (int c = 0; c < 4; ++c) {
      problem.AddResidualBlock(residuals::RoadSurfacePriorResidual::Create(RoadPlane(), 0.05),
                               nullptr, (*corners)[m][c].data());
    }
  }
  problem.AddResidualBlock(residuals::ExtrinsicPriorResidual::Create(prior), nullptr, extrinsic.q,
                           extrinsic.t);
  problem.SetManifold(extrinsic.q, new ceres::EigenQuaternionManifold);
  ceres::Solver::Options options;
  options.max_num_iterations = 100;
  options.function_tolerance = 1e-14;
  options.gradient_tolerance = 1e-14;
  options.parameter_tolerance = 1e-14;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  EXPECT_TRUE(summary.IsSolutionUsable()) << summary.BriefReport();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Map<const Eigen::Quaterniond>(extrinsic.q).normalized().toRotationMatrix();
  T.translation() = Eigen::Map<const Eigen::Vector3d>(extrinsic.t);
  return T;
}

ExtrinsicPrior MountingPrior(const Scene& scene) {
  return ExtrinsicPrior(scene.T_rough, Eigen::Vector3d::Constant(2.0 * kDeg),
                        Eigen::Vector3d::Constant(0.05));
}

TEST(ExtrinsicPrior, ChartRoundTripsAndStartsAtTheMountingValue) {
  const Scene scene;
  const ExtrinsicPrior prior = MountingPrior(scene);
  EXPECT_LT(prior.MeanDelta().norm(), 1e-12);
  const Eigen::Matrix<double, 6, 1> d = prior.DeltaOf(scene.T_true);
  EXPECT_LT((prior.FromDelta(d).matrix() - scene.T_true.matrix()).norm(), 1e-12);
  // The residual's cost is the prior's: 1/2 |r|^2 = 1/2 d^T H d (mean 0 here).
  std::unique_ptr<ceres::CostFunction> cost(residuals::ExtrinsicPriorResidual::Create(prior));
  const PoseBlock b = Blocks(scene.T_true);
  const double* blocks[2] = {b.q, b.t};
  Eigen::Matrix<double, 6, 1> r;
  ASSERT_TRUE(cost->Evaluate(blocks, r.data(), nullptr));
  EXPECT_NEAR(r.squaredNorm(), d.dot(prior.H() * d), 1e-9);
}

TEST(MarginalizeIntoExtrinsic, HalfMarginalizedEqualsTheJointSolution) {
  const Scene scene;
  std::vector<std::array<Eigen::Vector3d, 4>> corners;
  // The joint solution over all six markings.
  const Eigen::Isometry3d T_joint =
      SolveJoint(scene, {0, 1, 2, 3, 4, 5}, MountingPrior(scene), &corners);
  EXPECT_LT(RotationAngleBetween(T_joint, scene.T_true), 0.1 * kDeg);  // the data is good
  // Markings 0-2 alone, then marginalized at their solution; 3-5 solved with that prior.
  const ExtrinsicPrior mounting = MountingPrior(scene);
  const Eigen::Isometry3d T_first = SolveJoint(scene, {0, 1, 2}, mounting, &corners);
  MarginalizationInput input;
  for (int m = 0; m < 3; ++m) {
    for (int c = 0; c < 4; ++c) {
      input.points.push_back(corners[m][c]);
      input.road_priors.push_back({4 * m + c, RoadPlane(), 0.05});
    }
  }
  for (const Scene::Obs& o : scene.observations) {
    if (o.marking < 3)
      input.corners.push_back({4 * o.marking + o.corner, o.uv, scene.poses[o.pose]});
  }
  ExtrinsicPrior prior = mounting;
  prior.Add(MarginalizeIntoExtrinsic(scene.camera, prior, T_first, input, 1.0, 0.0));
  // The prior alone now says what the first half said.
  EXPECT_LT((prior.MeanDelta() - prior.DeltaOf(T_first)).norm(), 2e-4);
  const Eigen::Isometry3d T_sequential = SolveJoint(scene, {3, 4, 5}, prior, &corners);
  EXPECT_LT(RotationAngleBetween(T_sequential, T_joint), 0.01 * kDeg);
  EXPECT_LT((T_sequential.translation() - T_joint.translation()).norm(), 2e-3);
  // Without the first half's information the second half alone lands elsewhere.
  const Eigen::Isometry3d T_second_only = SolveJoint(scene, {3, 4, 5}, mounting, &corners);
  EXPECT_GT(RotationAngleBetween(T_second_only, T_joint) +
                (T_second_only.translation() - T_joint.translation()).norm(),
            RotationAngleBetween(T_sequential, T_joint) +
                (T_sequential.translation() - T_joint.translation()).norm());
}

// A factor saying "delta = mean" with information `information` * I.
ExtrinsicFactor FactorAt(const Eigen::Matrix<double, 6, 1>& mean, double information) {
  ExtrinsicFactor factor;
  factor.H = information * Eigen::Matrix<double, 6, 6>::Identity();
  factor.delta_lin = mean;  // linearized at its own minimum: g = 0
  return factor;
}

TEST(ExtrinsicPrior, ForgettingBoundsMemoryAndFollowsRecentData) {
  // 200 batches that say a, then 200 that say b. A plain sum averages them and its
  // information grows without bound; with a memory of 20 batches the prior follows b and
  // its information stays near 20 batches' worth.
  const Scene scene;
  Eigen::Matrix<double, 6, 1> a = Eigen::Matrix<double, 6, 1>::Constant(0.01);
  Eigen::Matrix<double, 6, 1> b = -a;
  ExtrinsicPrior sum(scene.T_rough, Eigen::Vector3d::Constant(2.0 * kDeg),
                     Eigen::Vector3d::Constant(0.05));
  ExtrinsicPrior forgetting(scene.T_rough, Eigen::Vector3d::Constant(2.0 * kDeg),
                            Eigen::Vector3d::Constant(0.05), 20.0);
  for (int k = 0; k < 400; ++k) {
    sum.Add(FactorAt(k < 200 ? a : b, 1e4));
    forgetting.Add(FactorAt(k < 200 ? a : b, 1e4));
  }
  EXPECT_LT(sum.MeanDelta().norm(), 1e-3);  // the average of a and b, near 0
  // (The mounting prior's pull toward 0 is under 1 % of 20 batches' information.)
  EXPECT_LT((forgetting.MeanDelta() - b).norm(), 1e-2 * b.norm());
  const double retired = (forgetting.H() - forgetting.H_mount()).trace() / 6.0;
  EXPECT_NEAR(retired, 20.0 * 1e4, 0.05 * 20.0 * 1e4);
  EXPECT_NEAR((sum.H() - sum.H_mount()).trace() / 6.0, 400.0 * 1e4, 1.0);
  // The mounting prior is never forgotten.
  EXPECT_EQ(forgetting.H_mount(), sum.H_mount());
}

TEST(MarginalizeIntoExtrinsic, EmptyInputGivesNoInformation) {
  const Scene scene;
  const ExtrinsicFactor factor = MarginalizeIntoExtrinsic(
      scene.camera, MountingPrior(scene), scene.T_rough, MarginalizationInput(), 1.0, 2.0);
  EXPECT_EQ(factor.H.norm(), 0.0);
  EXPECT_EQ(factor.g.norm(), 0.0);
}

}  // namespace
}  // namespace ipm_road_mapper
