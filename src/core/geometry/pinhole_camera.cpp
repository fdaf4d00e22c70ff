#include "ipm_road_mapper/core/geometry/pinhole_camera.h"

#include <cmath>
#include <sstream>

namespace ipm_road_mapper {

std::string PinholeCamera::Validate() const {
  std::ostringstream error;
  if (in_.width <= 0 || in_.height <= 0) {
    error << "image size " << in_.width << "x" << in_.height << " is not positive";
  } else if (!(in_.fx > 0.0) || !(in_.fy > 0.0) || !std::isfinite(in_.fx) ||
             !std::isfinite(in_.fy)) {
    error << "focal lengths fx=" << in_.fx << " fy=" << in_.fy << " must be finite and > 0";
  } else if (!std::isfinite(in_.cx) || !std::isfinite(in_.cy)) {
    error << "principal point is not finite";
  } else {
    for (double d : in_.distortion) {
      if (!std::isfinite(d)) error << "distortion coefficient is not finite";
      if (!std::isfinite(d)) break;
    }
  }
  return error.str();
}

Eigen::Matrix3d PinholeCamera::K() const {
  Eigen::Matrix3d K;
  K << in_.fx, 0.0, in_.cx, 0.0, in_.fy, in_.cy, 0.0, 0.0, 1.0;
  return K;
}

bool PinholeCamera::HasDistortion() const {
  for (double d : in_.distortion) {
    if (d != 0.0) return true;
  }
  return false;
}

Eigen::Matrix2d PinholeCamera::DistortionJacobian(const Eigen::Vector2d& xy) const {
  // With r2 = x^2 + y^2, radial = 1 + k1 r2 + k2 r2^2 + k3 r2^3, a = d radial / d r2:
  //   xd = x radial + 2 p1 x y + p2 (r2 + 2 x^2)
  //   yd = y radial + p1 (r2 + 2 y^2) + 2 p2 x y
  const auto& d = in_.distortion;
  const double x = xy.x(), y = xy.y();
  const double r2 = x * x + y * y;
  const double radial = 1.0 + r2 * (d[0] + r2 * (d[1] + r2 * d[4]));
  const double a = d[0] + r2 * (2.0 * d[1] + 3.0 * r2 * d[4]);
  const double cross = 2.0 * x * y * a + 2.0 * d[2] * x + 2.0 * d[3] * y;
  Eigen::Matrix2d J;
  J << radial + 2.0 * x * x * a + 2.0 * d[2] * y + 6.0 * d[3] * x, cross, cross,
      radial + 2.0 * y * y * a + 6.0 * d[2] * y + 2.0 * d[3] * x;
  return J;
}

}  // namespace ipm_road_mapper
