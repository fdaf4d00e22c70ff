#include "ipm_road_mapper/core/backend/pose_covariance.h"

#include <ceres/covariance.h>

#include <utility>
#include <vector>

namespace ipm_road_mapper {
namespace {

Eigen::Matrix3d Hat(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

}  // namespace

bool ComputePoseCovariance(ceres::Problem* problem, const double* q, const double* t,
                           PoseCovariance* covariance) {
  if (!problem->HasParameterBlock(q) || !problem->HasParameterBlock(t)) return false;
  if (problem->IsParameterBlockConstant(q) || problem->IsParameterBlockConstant(t)) return false;
  ceres::Covariance::Options options;
  options.num_threads = 1;
  ceres::Covariance estimator(options);
  const std::vector<std::pair<const double*, const double*>> blocks = {{q, q}, {q, t}, {t, t}};
  if (!estimator.Compute(blocks, problem)) return false;
  // Tangent order (rotation, translation); the message's is (translation, rotation). The
  // manifold's rotation tangent is half the rotation vector (Plus takes the quaternion
  // [cos|d|, sin|d| d/|d|], a rotation by 2|d|): theta = 2 d.
  Eigen::Matrix<double, 6, 6, Eigen::RowMajor> tangent;
  if (!estimator.GetCovarianceMatrixInTangentSpace({q, t}, tangent.data())) return false;
  PoseCovariance out;
  out.topLeftCorner<3, 3>() = tangent.bottomRightCorner<3, 3>();
  out.bottomRightCorner<3, 3>() = 4.0 * tangent.topLeftCorner<3, 3>();
  out.topRightCorner<3, 3>() = 2.0 * tangent.bottomLeftCorner<3, 3>();
  out.bottomLeftCorner<3, 3>() = 2.0 * tangent.topRightCorner<3, 3>();
  if (!out.allFinite()) return false;
  *covariance = out;
  return true;
}

PoseCovariance OdometryPoseCovariance(const Eigen::Isometry3d& T_map_base,
                                      const Eigen::Vector3d& sigma_trans_m,
                                      const Eigen::Vector3d& sigma_rot_rad) {
  const Eigen::Matrix3d R = T_map_base.linear();
  PoseCovariance out = PoseCovariance::Zero();
  out.topLeftCorner<3, 3>() = R * sigma_trans_m.cwiseAbs2().asDiagonal() * R.transpose();
  out.bottomRightCorner<3, 3>() = R * sigma_rot_rad.cwiseAbs2().asDiagonal() * R.transpose();
  return out;
}

PoseCovariance PropagatePoseCovariance(const PoseCovariance& covariance_opt,
                                       const Eigen::Isometry3d& T_map_base_opt,
                                       const Eigen::Isometry3d& T_map_base_new,
                                       const PoseCovariance& odometry_new) {
  PoseCovariance J = PoseCovariance::Identity();
  J.topRightCorner<3, 3>() = -Hat(T_map_base_new.translation() - T_map_base_opt.translation());
  return J * covariance_opt * J.transpose() + odometry_new;
}

}  // namespace ipm_road_mapper
