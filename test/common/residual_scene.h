// The scene the residual tests share (test_residuals, test_pose_residuals,
// test_residual_solves): a 1280x720 camera with mild plumb_bob distortion, 1.5 m high and
// 1.5 m ahead of base_link, pitched down 5 deg; a vehicle pose with yaw and translation;
// poses as Ceres parameter blocks; a reference projection written without projection.h;
// the gradient check of a cost function on its manifolds; and the fixture over them.
#pragma once

#include <ceres/ceres.h>
#include <ceres/gradient_checker.h>
#include <ceres/manifold.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "common/test_scene.h"
#include "common/units.h"
#include "ipm_road_mapper/core/geometry/pinhole_camera.h"
#include "ipm_road_mapper/core/geometry/rigid_transform.h"

namespace ipm_road_mapper {
namespace residuals {

// Relative precision of the gradient checks. The residuals never run the distortion's
// Newton inversion (only the forward model), so autodiff and Ridders' differences agree
// far below this (worst observed: 7e-10 for the corner reprojection, 2e-12 for PPSR,
// 1e-13 for PSR and the priors).
constexpr double kGradientPrecision = 1e-7;

// ---------------------------------------------------------------------------------------
// Scene: 1280x720 camera with mild plumb_bob distortion, 1.5 m high and 1.5 m ahead of
// base_link, looking forward and pitched down 5 deg; a vehicle pose with yaw and
// translation (and a little roll and pitch, so no axis is special); ground points ahead.

inline PinholeCamera TestCamera() {
  return PinholeCamera(test::Intrinsics1280x720(640.0, 360.0, test::kMildDistortion));
}

inline Eigen::Isometry3d Extrinsic(double pitch_rad) {
  return test::MountedCamera(0.0, pitch_rad, 0.0);
}

// Pitch of the camera rig encoded in an extrinsic rotation (inverse of Extrinsic()).
inline double ExtrinsicPitch(const Eigen::Matrix3d& R_base_cam) {
  return RpyFromRotation(R_base_cam * test::BaseOpticalAxes().transpose())(1);
}

inline Eigen::Isometry3d VehiclePose() {
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

inline PoseBlocks ToBlocks(const Eigen::Isometry3d& T) {
  PoseBlocks blocks;
  Eigen::Map<Eigen::Vector4d>(blocks.q.data()) = Eigen::Quaterniond(T.linear()).coeffs();
  Eigen::Map<Eigen::Vector3d>(blocks.t.data()) = T.translation();
  return blocks;
}

inline PoseBlocks Negated(const PoseBlocks& blocks) {
  PoseBlocks negated = blocks;
  for (double& c : negated.q) c = -c;
  return negated;
}

inline Eigen::Isometry3d FromBlocks(const PoseBlocks& blocks) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Quaterniond(blocks.q[3], blocks.q[0], blocks.q[1], blocks.q[2])
                   .normalized()
                   .toRotationMatrix();
  T.translation() = Eigen::Vector3d(blocks.t[0], blocks.t[1], blocks.t[2]);
  return T;
}

// Reference projection, written without projection.h: p_cam = T_cam_base T_base_map p.
inline Eigen::Vector2d ReferenceProjection(const PinholeCamera& camera,
                                           const Eigen::Isometry3d& T_map_base,
                                           const Eigen::Isometry3d& T_base_cam,
                                           const Eigen::Vector3d& p_map) {
  const Eigen::Vector3d p_cam = (T_base_cam.inverse() * T_map_base.inverse()) * p_map;
  Eigen::Vector2d uv;
  EXPECT_TRUE(camera.Project(p_cam, &uv));
  return uv;
}

// Residuals of a cost function at `parameters` (no Jacobians).
inline Eigen::VectorXd Evaluate(const ceres::CostFunction& cost,
                                const std::vector<const double*>& parameters) {
  Eigen::VectorXd residuals(cost.num_residuals());
  EXPECT_TRUE(cost.Evaluate(parameters.data(), residuals.data(), nullptr));
  return residuals;
}

// Compares the autodiff Jacobians with Ridders' differences, in the manifolds' tangent
// spaces (nullptr: Euclidean block).
inline void ExpectJacobiansMatch(const ceres::CostFunction& cost,
                                 const std::vector<const ceres::Manifold*>& manifolds,
                                 const std::vector<const double*>& parameters,
                                 double relative_precision) {
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

inline const ceres::EigenQuaternionManifold kQuaternionManifold;

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

}  // namespace residuals
}  // namespace ipm_road_mapper
