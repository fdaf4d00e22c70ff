#include "ipm_road_mapper/core/geometry/road_surface.h"

#include <limits>

#include "ipm_road_mapper/core/geometry/ipm.h"

namespace ipm_road_mapper {

RoadSurfaceEstimate RoadSurfaceNear(const std::vector<Eigen::Isometry3d>& T_map_base,
                                    const Eigen::Vector3d& p_map, double radius_m) {
  if (T_map_base.empty()) return RoadSurfaceEstimate();
  double closest = std::numeric_limits<double>::infinity();
  std::size_t closest_index = 0;
  std::vector<const Eigen::Isometry3d*> within;
  for (std::size_t i = 0; i < T_map_base.size(); ++i) {
    const double d = (T_map_base[i].translation() - p_map).head<2>().norm();
    if (d < closest) {
      closest = d;
      closest_index = i;
    }
    if (d <= radius_m) within.push_back(&T_map_base[i]);
  }
  return RoadSurfaceFromPoses(within, T_map_base[closest_index], closest, p_map);
}

RoadSurfaceEstimate RoadSurfaceFromPoses(const std::vector<const Eigen::Isometry3d*>& within,
                                         const Eigen::Isometry3d& T_map_base_closest,
                                         double closest_distance_m, const Eigen::Vector3d& p_map) {
  RoadSurfaceEstimate estimate;
  estimate.lateral_m = (T_map_base_closest.inverse() * p_map).y();
  Eigen::Vector3d origin_sum = Eigen::Vector3d::Zero(), normal_sum = Eigen::Vector3d::Zero();
  for (const Eigen::Isometry3d* T : within) {
    origin_sum += T->translation();
    normal_sum += T->linear().col(2);
  }
  estimate.frames = static_cast<int>(within.size());
  estimate.distance_m = closest_distance_m;
  if (estimate.frames == 0) {
    estimate.frames = 1;
    origin_sum = T_map_base_closest.translation();
    normal_sum = T_map_base_closest.linear().col(2);
  } else {
    origin_sum /= estimate.frames;
  }
  estimate.plane.point = origin_sum;
  estimate.plane.normal = normal_sum.normalized();
  if (estimate.plane.normal.z() < 0.0) estimate.plane.normal = -estimate.plane.normal;
  return estimate;
}

bool PixelOntoPlane(const PinholeCamera& camera, const Eigen::Isometry3d& T_map_cam,
                    const RoadPlane& plane, const Eigen::Vector2d& uv, Eigen::Vector3d* p_map) {
  if (!uv.allFinite()) return false;
  const Eigen::Vector2d xy = camera.UndistortToNormalized(uv);
  const Eigen::Vector3d ray_map = T_map_cam.linear() * Eigen::Vector3d(xy.x(), xy.y(), 1.0);
  const double descent = plane.normal.dot(ray_map);
  if (!(descent < -Ipm::kMinRayDescent * ray_map.norm())) return false;
  const double lambda = plane.normal.dot(plane.point - T_map_cam.translation()) / descent;
  if (!(lambda > 0.0)) return false;
  *p_map = T_map_cam.translation() + lambda * ray_map;
  return true;
}

}  // namespace ipm_road_mapper
