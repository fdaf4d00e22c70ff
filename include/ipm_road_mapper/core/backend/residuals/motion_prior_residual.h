// Motion prior over three consecutive poses: the vehicle's acceleration, linear and angular,
// is small at the camera's rate. With v_a = (t_1 - t_0) / dt_a, v_b = (t_2 - t_1) / dt_b and
// the body-frame rotation increments w_a = Log(R_0^T R_1) / dt_a, w_b = Log(R_1^T R_2) / dt_b,
//   r = [ R_1^T (v_b - v_a) / (dt sigma_acc) ; (w_b - w_a) / (dt sigma_angular_acc) ]
// with dt = (dt_a + dt_b) / 2: finite-difference accelerations, in base_link axes of the
// middle pose, per axis. Why: odometry's pose-to-pose random error (the paper's protocol:
// 0.1-0.5 m on each pose) has no physical counterpart (a car at 10 m/s does not jump by
// decimeters in 50 ms), so the pose step may smooth it; the measurements and the odometry
// prior still decide where the trajectory is. It cannot remove a smooth drift, which only
// markings correct. Log is ceres::QuaternionToAngleAxis (exact, with its small-angle
// branch smooth for autodiff).
// Parameter blocks: q0[4], t0[3], q1[4], t1[3], q2[4], t2[3] (map_T_base of each frame).
#pragma once

#include <ceres/autodiff_cost_function.h>

#include <Eigen/Geometry>

#include "ipm_road_mapper/core/backend/residuals/rotation_vector.h"

namespace ipm_road_mapper {
namespace residuals {

class MotionPriorResidual {
 public:
  MotionPriorResidual(double dt_a, double dt_b, const Eigen::Vector3d& sigma_acc_mps2,
                      const Eigen::Vector3d& sigma_angular_acc_radps2)
      : dt_a_(dt_a),
        dt_b_(dt_b),
        inv_linear_((0.5 * (dt_a + dt_b) * sigma_acc_mps2).cwiseInverse()),
        inv_angular_((0.5 * (dt_a + dt_b) * sigma_angular_acc_radps2).cwiseInverse()) {}

  template <typename T>
  bool operator()(const T* const q0, const T* const t0, const T* const q1, const T* const t1,
                  const T* const q2, const T* const t2, T* residual) const {
    using Q = Eigen::Quaternion<T>;
    using V = Eigen::Matrix<T, 3, 1>;
    const Eigen::Map<const Q> Q0(q0), Q1(q1), Q2(q2);
    const Eigen::Map<const V> T0(t0), T1(t1), T2(t2);
    const V v_a = (T1 - T0) / T(dt_a_), v_b = (T2 - T1) / T(dt_b_);
    const V dv = Q1.conjugate() * (v_b - v_a);
    const V w_a = RotationVector(Q0.conjugate() * Q1) / T(dt_a_);
    const V w_b = RotationVector(Q1.conjugate() * Q2) / T(dt_b_);
    for (int i = 0; i < 3; ++i) {
      residual[i] = dv(i) * T(inv_linear_(i));
      residual[3 + i] = (w_b(i) - w_a(i)) * T(inv_angular_(i));
    }
    return true;
  }

  static ceres::CostFunction* Create(double dt_a, double dt_b, const Eigen::Vector3d& sigma_acc,
                                     const Eigen::Vector3d& sigma_angular_acc) {
    return new ceres::AutoDiffCostFunction<MotionPriorResidual, 6, 4, 3, 4, 3, 4, 3>(
        new MotionPriorResidual(dt_a, dt_b, sigma_acc, sigma_angular_acc));
  }

 private:
  double dt_a_, dt_b_;
  Eigen::Vector3d inv_linear_, inv_angular_;
};

}  // namespace residuals
}  // namespace ipm_road_mapper
