// Pinhole camera with plumb_bob (OpenCV 5-coefficient) distortion, in the camera optical
// frame (z forward, x right, y down). Projection is templated so Ceres residuals can
// autodiff through it.
#pragma once

#include <Eigen/Core>
#include <Eigen/LU>  // Matrix::inverse() in UndistortToNormalized
#include <array>
#include <cmath>
#include <string>

#include "ipm_road_mapper/core/geometry/scalar.h"

namespace ipm_road_mapper {

// Intrinsics as sensor_msgs/CameraInfo carries them (K and D of a plumb_bob model).
struct CameraIntrinsics {
  int width = 0;
  int height = 0;
  double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0;
  std::array<double, 5> distortion{{0.0, 0.0, 0.0, 0.0, 0.0}};  // k1, k2, p1, p2, k3
};

// Projects camera-frame points to pixels and back-projects pixels to rays.
class PinholeCamera {
 public:
  // Points closer than this along the optical axis are not projected (near plane, m).
  static constexpr double kMinDepth = 1e-3;

  PinholeCamera() = default;
  explicit PinholeCamera(const CameraIntrinsics& intrinsics) : in_(intrinsics) {}

  // Empty when the intrinsics are usable, otherwise what is wrong with them.
  std::string Validate() const;

  const CameraIntrinsics& intrinsics() const { return in_; }
  int width() const { return in_.width; }
  int height() const { return in_.height; }
  Eigen::Matrix3d K() const;
  bool HasDistortion() const;

  // Applies plumb_bob distortion to a normalized image point (x/z, y/z).
  template <typename T>
  Eigen::Matrix<T, 2, 1> Distort(const Eigen::Matrix<T, 2, 1>& xy) const {
    const auto& d = in_.distortion;
    const T x = xy(0), y = xy(1);
    const T r2 = x * x + y * y;
    const T radial = T(1.0) + r2 * (T(d[0]) + r2 * (T(d[1]) + r2 * T(d[4])));
    return {x * radial + T(2.0 * d[2]) * x * y + T(d[3]) * (r2 + T(2.0) * x * x),
            y * radial + T(d[2]) * (r2 + T(2.0) * y * y) + T(2.0 * d[3]) * x * y};
  }

  // Projects a point in the camera optical frame to a pixel. Returns false when the point
  // is not in front of the camera (z < kMinDepth); the image bounds are not checked.
  template <typename T>
  bool Project(const Eigen::Matrix<T, 3, 1>& p_cam, Eigen::Matrix<T, 2, 1>* uv) const {
    if (p_cam(2) < T(kMinDepth)) return false;
    const Eigen::Matrix<T, 2, 1> xy(p_cam(0) / p_cam(2), p_cam(1) / p_cam(2));
    const Eigen::Matrix<T, 2, 1> xy_d = Distort(xy);
    (*uv)(0) = T(in_.fx) * xy_d(0) + T(in_.cx);
    (*uv)(1) = T(in_.fy) * xy_d(1) + T(in_.cy);
    return true;
  }

  // Inverse of Distort o normalize: pixel -> undistorted normalized point (x/z, y/z).
  // Gauss-Newton on the distortion model, converged to 1e-12; templated for autodiff.
  template <typename T>
  Eigen::Matrix<T, 2, 1> UndistortToNormalized(const Eigen::Matrix<T, 2, 1>& uv) const;

  // Pixel -> ray direction in the camera frame, scaled so that z = 1.
  Eigen::Vector3d Unproject(const Eigen::Vector2d& uv) const {
    const Eigen::Vector2d xy = UndistortToNormalized(uv);
    return {xy.x(), xy.y(), 1.0};
  }

  // True when the pixel lies inside the image, at least `margin_px` from its border.
  bool InImage(const Eigen::Vector2d& uv, double margin_px = 0.0) const {
    return uv.x() >= margin_px && uv.y() >= margin_px && uv.x() <= in_.width - 1 - margin_px &&
           uv.y() <= in_.height - 1 - margin_px;
  }

 private:
  // d Distort / d xy at a normalized point (analytic).
  Eigen::Matrix2d DistortionJacobian(const Eigen::Vector2d& xy) const;

  CameraIntrinsics in_;
};

template <typename T>
Eigen::Matrix<T, 2, 1> PinholeCamera::UndistortToNormalized(
    const Eigen::Matrix<T, 2, 1>& uv) const {
  const Eigen::Matrix<T, 2, 1> xy_d((uv(0) - T(in_.cx)) / T(in_.fx),
                                    (uv(1) - T(in_.cy)) / T(in_.fy));
  if (!HasDistortion()) return xy_d;
  Eigen::Matrix<T, 2, 1> xy = xy_d;
  // Newton iterations on Distort(xy) = xy_d. The Jacobian is taken at the double value;
  // for Jets the derivative part then converges linearly at a rate of the Jacobian's
  // rounding error, so a few iterations past value convergence make it exact too.
  int converged_iterations = 0;
  for (int iteration = 0; iteration < 30 && converged_iterations < 3; ++iteration) {
    const Eigen::Matrix<T, 2, 1> error = Distort(xy) - xy_d;
    const Eigen::Vector2d x0(ScalarValue(xy(0)), ScalarValue(xy(1)));
    const Eigen::Matrix2d J_inv = DistortionJacobian(x0).inverse();
    xy -= J_inv.cast<T>() * error;
    if (std::abs(ScalarValue(error(0))) + std::abs(ScalarValue(error(1))) < 1e-14) {
      ++converged_iterations;
    }
  }
  return xy;
}

}  // namespace ipm_road_mapper
