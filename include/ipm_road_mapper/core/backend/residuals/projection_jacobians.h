// Analytic Jacobians of the projection chain of projection.h, for the step bindings of the
// reprojection residuals (autodiff of a two-point PPSR costs ~5 us a block; the solves
// evaluate thousands of blocks per iteration).
//
// Pixel of a camera-frame point p = (X, Y, Z): x = X / Z, y = Y / Z, plumb_bob distortion
//   r2 = x^2 + y^2,  k = 1 + k1 r2 + k2 r2^2 + k3 r2^3
//   xd = x k + 2 p1 x y + p2 (r2 + 2 x^2),   yd = y k + p1 (r2 + 2 y^2) + 2 p2 x y
//   u = fx xd + cx,  v = fy yd + cy
// so d uv / d p = diag(fx, fy) (d(xd, yd) / d(x, y)) [1/Z 0 -X/Z^2 ; 0 1/Z -Y/Z^2].
//
// Inverse rotation by a unit quaternion q = (w, u) (Eigen storage x, y, z, w):
//   R(q)^T v = v - 2 w (u x v) + 2 u x (u x v) = v - 2 w (u x v) + 2 (u (u.v) - v (u.u))
//   d/dw = -2 (u x v),   d/du = 2 w [v]x + 2 (u v^T + (u.v) I - 2 v u^T)
// Derivatives in the ambient quaternion coordinates: Ceres's EigenQuaternionManifold maps
// them to its tangent (the formula holds on the unit sphere, whose tangent directions are
// all the manifold uses).
#pragma once

#include <Eigen/Geometry>

#include "ipm_road_mapper/core/geometry/pinhole_camera.h"

namespace ipm_road_mapper {
namespace residuals {

// Pixel of p_cam and d uv / d p_cam; false when p_cam is not in front of the camera.
inline bool ProjectWithJacobian(const PinholeCamera& camera, const Eigen::Vector3d& p_cam,
                                Eigen::Vector2d* uv, Eigen::Matrix<double, 2, 3>* J) {
  if (p_cam.z() < PinholeCamera::kMinDepth) return false;
  const CameraIntrinsics& in = camera.intrinsics();
  const double inv_z = 1.0 / p_cam.z();
  const double x = p_cam.x() * inv_z, y = p_cam.y() * inv_z;
  const auto& d = in.distortion;
  const double k1 = d[0], k2 = d[1], p1 = d[2], p2 = d[3], k3 = d[4];
  const double r2 = x * x + y * y;
  const double k = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
  const double dk_dr2 = k1 + r2 * (2.0 * k2 + 3.0 * r2 * k3);
  const double xd = x * k + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x);
  const double yd = y * k + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y;
  (*uv) << in.fx * xd + in.cx, in.fy * yd + in.cy;
  if (J) {
    Eigen::Matrix2d D;  // d(xd, yd) / d(x, y)
    D(0, 0) = k + 2.0 * x * x * dk_dr2 + 2.0 * p1 * y + 6.0 * p2 * x;
    D(0, 1) = 2.0 * x * y * dk_dr2 + 2.0 * p1 * x + 2.0 * p2 * y;
    D(1, 0) = 2.0 * x * y * dk_dr2 + 2.0 * p1 * x + 2.0 * p2 * y;
    D(1, 1) = k + 2.0 * y * y * dk_dr2 + 6.0 * p1 * y + 2.0 * p2 * x;
    Eigen::Matrix<double, 2, 3> P;
    P << inv_z, 0.0, -x * inv_z, 0.0, inv_z, -y * inv_z;
    *J = Eigen::Vector2d(in.fx, in.fy).asDiagonal() * D * P;
  }
  return true;
}

// d (R(q)^T v) / d q in ambient coordinates (columns x, y, z, w), q of unit length.
inline Eigen::Matrix<double, 3, 4> InverseRotationJacobian(const double* q_xyzw,
                                                           const Eigen::Vector3d& v) {
  const Eigen::Vector3d u(q_xyzw[0], q_xyzw[1], q_xyzw[2]);
  const double w = q_xyzw[3];
  Eigen::Matrix3d v_hat;
  v_hat << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  Eigen::Matrix<double, 3, 4> J;
  J.leftCols<3>() =
      2.0 * w * v_hat +
      2.0 * (u * v.transpose() + u.dot(v) * Eigen::Matrix3d::Identity() - 2.0 * v * u.transpose());
  J.col(3) = -2.0 * u.cross(v);
  return J;
}

// Writes a fixed-size matrix (residuals, or a Jacobian block) into Ceres' row-major array.
template <typename Derived>
inline void StoreRowMajor(const Eigen::MatrixBase<Derived>& m, double* out) {
  for (Eigen::Index r = 0; r < m.rows(); ++r) {
    for (Eigen::Index c = 0; c < m.cols(); ++c) out[r * m.cols() + c] = m(r, c);
  }
}

}  // namespace residuals
}  // namespace ipm_road_mapper
