#include "ipm_road_mapper/core/mapper/odometry_correction.h"

namespace ipm_road_mapper {

Eigen::Isometry3d FitOdometryCorrection(const std::vector<FrameRecord>& frames,
                                        const std::vector<std::size_t>& solved) {
  Eigen::Isometry3d T_map_odom = Eigen::Isometry3d::Identity();
  if (solved.empty()) return T_map_odom;
  // Rotation: the normalized sum of the per-frame correction quaternions, each on the
  // hemisphere of the first (the chordal L2 mean; exact enough for corrections of degrees).
  Eigen::Vector4d q_sum = Eigen::Vector4d::Zero();
  Eigen::Vector3d t_map_mean = Eigen::Vector3d::Zero(), t_odom_mean = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_first;
  for (std::size_t k = 0; k < solved.size(); ++k) {
    const FrameRecord& f = frames[solved[k]];
    Eigen::Quaterniond q(f.T_map_base.linear() * f.T_map_base_odom.linear().transpose());
    q.normalize();
    if (k == 0) q_first = q;
    if (q.coeffs().dot(q_first.coeffs()) < 0.0) q.coeffs() = -q.coeffs();
    q_sum += q.coeffs();
    t_map_mean += f.T_map_base.translation();
    t_odom_mean += f.T_map_base_odom.translation();
  }
  const double n = static_cast<double>(solved.size());
  t_map_mean /= n;
  t_odom_mean /= n;
  Eigen::Quaterniond q_mean;
  q_mean.coeffs() = q_sum.normalized();
  T_map_odom.linear() = q_mean.toRotationMatrix();
  T_map_odom.translation() = t_map_mean - T_map_odom.linear() * t_odom_mean;
  return T_map_odom;
}

}  // namespace ipm_road_mapper
