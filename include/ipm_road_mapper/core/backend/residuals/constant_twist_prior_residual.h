// Constant-twist motion prior over three consecutive poses: the vehicle's velocity in its own
// body frame and its angular rate change little at the camera's rate. With the body-frame
// velocities of the two steps, each in the axes of the pose it starts from,
//   u_a = R_0^T (t_1 - t_0) / dt_a,  u_b = R_1^T (t_2 - t_1) / dt_b,
// and the body-frame rotation increments w_a = Log(R_0^T R_1) / dt_a, w_b = Log(R_1^T R_2) / dt_b,
//   r = [ (u_b - u_a) / (dt sigma_acc) ; (w_b - w_a) / (dt sigma_angular_acc) ]
// with dt = (dt_a + dt_b) / 2, per base_link axis. Why not MotionPriorResidual (the map-frame
// acceleration R_1^T (v_b - v_a)): on a constant-speed turn its residual is the centripetal
// acceleration v^2 / r (0.5 m/s^2 at 10 m/s on a 200 m curve), so where little else holds
// the poses (the newest poses after a solve, pose_extrapolator.h) it pulls them towards a
// straight line, outwards of every curve. Here a chord of an arc seen from its start pose
// points at half the turn for both steps, so a constant-speed, constant-yaw-rate arc is an
// exact zero (equal steps) and the prior penalizes only changes of speed, of side slip and of
// turn rate. Log is ceres::QuaternionToAngleAxis (exact, smooth for autodiff).
// Parameter blocks: q0[4], t0[3], q1[4], t1[3], q2[4], t2[3] (map_T_base of each frame).
#pragma once

#include <ceres/autodiff_cost_function.h>

#include <Eigen/Geometry>

#include "ipm_road_mapper/core/backend/residuals/rotation_vector.h"

namespace ipm_road_mapper {
namespace residuals {

class ConstantTwistPriorResidual {
 public:
  // Steps dt_a, dt_b (s) between the three poses; sigmas per base_link axis.
  ConstantTwistPriorResidual(double dt_a, double dt_b, const Eigen::Vector3d& sigma_acc_mps2,
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
    const V u_a = Q0.conjugate() * ((T1 - T0) / T(dt_a_));
    const V u_b = Q1.conjugate() * ((T2 - T1) / T(dt_b_));
    const V w_a = RotationVector(Q0.conjugate() * Q1) / T(dt_a_);
    const V w_b = RotationVector(Q1.conjugate() * Q2) / T(dt_b_);
    for (int i = 0; i < 3; ++i) {
      residual[i] = (u_b(i) - u_a(i)) * T(inv_linear_(i));
      residual[3 + i] = (w_b(i) - w_a(i)) * T(inv_angular_(i));
    }
    return true;
  }

  // The autodiff cost function (6 residuals; blocks 4, 3, 4, 3, 4, 3).
  static ceres::CostFunction* Create(double dt_a, double dt_b, const Eigen::Vector3d& sigma_acc,
                                     const Eigen::Vector3d& sigma_angular_acc) {
    return new ceres::AutoDiffCostFunction<ConstantTwistPriorResidual, 6, 4, 3, 4, 3, 4, 3>(
        new ConstantTwistPriorResidual(dt_a, dt_b, sigma_acc, sigma_angular_acc));
  }

 private:
  double dt_a_, dt_b_;
  Eigen::Vector3d inv_linear_, inv_angular_;
};

}  // namespace residuals
}  // namespace ipm_road_mapper
