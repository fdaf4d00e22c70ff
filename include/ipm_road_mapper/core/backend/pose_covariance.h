// The covariance of a vehicle pose T_map_base, in the convention of nav_msgs/Odometry: a 6x6
// matrix over (x, y, z, rotation about map x, y, z), both perturbations in the axes of `map`
// (T' = Exp(dtheta) T for the rotation, t' = t + dt for the translation, as the pose step's
// parameter blocks: a translation and a quaternion on ceres::EigenQuaternionManifold, whose
// Plus multiplies on the left; its tangent is half the rotation vector, scaled here).
//
// Two uses: the Ceres covariance of one pose of the pose step (the information of its
// residuals at the solution), and carrying that covariance to a newer frame along the
// odometry. With the correction C = T_opt T_odom_opt^-1 and T_new = C T_odom_new, a
// perturbation (dt, dtheta) of T_opt moves T_new by
//   dtheta_new = dtheta,  dt_new = dt + dtheta x d = dt - [d]x dtheta,  d = t_new - t_opt,
// and the new frame's own odometry error (its per-pose noise, base_link axes) adds on top:
//   Sigma_new = J Sigma_opt J^T + R_new Sigma_odom R_new^T (per block),  J = [I -[d]x; 0 I].
#pragma once

#include <ceres/problem.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace ipm_road_mapper {

// (x, y, z, rot x, rot y, rot z) in map axes.
using PoseCovariance = Eigen::Matrix<double, 6, 6>;

// The covariance of the pose held in the problem's blocks q[4] (Eigen order x y z w, on
// EigenQuaternionManifold) and t[3], at their current values. False when Ceres cannot
// compute it (rank-deficient: the pose is not determined).
bool ComputePoseCovariance(ceres::Problem* problem, const double* q, const double* t,
                           PoseCovariance* covariance);

// The odometry's own per-pose noise as a covariance (sigmas in base_link axes: translation
// x y z in m, rotation roll pitch yaw in rad), rotated into map axes at T_map_base.
PoseCovariance OdometryPoseCovariance(const Eigen::Isometry3d& T_map_base,
                                      const Eigen::Vector3d& sigma_trans_m,
                                      const Eigen::Vector3d& sigma_rot_rad);

// Carries `covariance_opt` of T_map_base_opt to T_map_base_new (the same correction, a later
// odometry pose) and adds `odometry_new`, the new frame's own odometry noise.
PoseCovariance PropagatePoseCovariance(const PoseCovariance& covariance_opt,
                                       const Eigen::Isometry3d& T_map_base_opt,
                                       const Eigen::Isometry3d& T_map_base_new,
                                       const PoseCovariance& odometry_new);

}  // namespace ipm_road_mapper
