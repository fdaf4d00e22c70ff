#include "ipm_road_mapper/core/frontend/marking_measurement.h"

#include <algorithm>
#include <limits>

#include "ipm_road_mapper/core/frontend/association.h"

namespace ipm_road_mapper {

bool MeasureCornersOnPlane(const PinholeCamera& camera, const Eigen::Isometry3d& T_map_cam,
                           const RoadPlane& plane, const Eigen::Vector3d& axis_map,
                           const std::array<Eigen::Vector3d, 4>& reference_corners_map,
                           const std::vector<Eigen::Vector2d>& outline_uv,
                           std::array<Eigen::Vector2d, 4>* corners_uv) {
  if (outline_uv.empty() || !(plane.normal.norm() > 0.0)) return false;
  // Up, so that the rectangle below is counter-clockwise seen from above like the reference.
  const Eigen::Vector3d n = plane.normal.normalized() * (plane.normal.z() < 0.0 ? -1.0 : 1.0);
  // In-plane axes: the road's direction, and the normal's cross product with it.
  Eigen::Vector3d axis = axis_map;
  axis -= n * n.dot(axis);
  if (axis.norm() < 1e-9) return false;
  axis.normalize();
  const Eigen::Vector3d across = n.cross(axis);
  const Eigen::Vector3d center = T_map_cam.translation();
  double a_min = std::numeric_limits<double>::infinity(), a_max = -a_min;
  double c_min = a_min, c_max = -a_min;
  for (const Eigen::Vector2d& uv : outline_uv) {
    const Eigen::Vector2d xy = camera.UndistortToNormalized(uv);
    const Eigen::Vector3d ray = T_map_cam.linear() * Eigen::Vector3d(xy.x(), xy.y(), 1.0);
    const double denominator = n.dot(ray);
    if (std::abs(denominator) < 1e-12) return false;
    const double t = n.dot(plane.point - center) / denominator;
    if (!(t > 0.0)) return false;  // the plane is behind this ray: at or above its horizon
    const Eigen::Vector3d d = center + t * ray - plane.point;
    a_min = std::min(a_min, d.dot(axis));
    a_max = std::max(a_max, d.dot(axis));
    c_min = std::min(c_min, d.dot(across));
    c_max = std::max(c_max, d.dot(across));
  }
  const std::array<Eigen::Vector3d, 4> corners = {
      plane.point + a_min * axis + c_min * across, plane.point + a_max * axis + c_min * across,
      plane.point + a_max * axis + c_max * across, plane.point + a_min * axis + c_max * across};
  // The corners in the reference's order: reference[i] ~ corners[(i + shift) % 4], the shift
  // that runs the sides alike (a partial view's rectangle is smaller than the reference:
  // the nearest corners need not be the same ones).
  int shift = 0;
  double best = -std::numeric_limits<double>::infinity();
  for (int k = 0; k < 4; ++k) {
    double agreement = 0.0;
    for (int i = 0; i < 4; ++i) {
      agreement += (reference_corners_map[(i + 1) % 4] - reference_corners_map[i])
                       .normalized()
                       .dot((corners[(i + 1 + k) % 4] - corners[(i + k) % 4]).normalized());
    }
    if (agreement > best) {
      best = agreement;
      shift = k;
    }
  }
  const Eigen::Isometry3d T_cam_map = T_map_cam.inverse();
  for (int i = 0; i < 4; ++i) {
    // A corner behind the camera is one a partial view cut: NaN, never a measurement.
    if (!camera.Project(Eigen::Vector3d(T_cam_map * corners[(i + shift) % 4]), &(*corners_uv)[i])) {
      (*corners_uv)[i] = Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
    }
  }
  return true;
}

}  // namespace ipm_road_mapper
