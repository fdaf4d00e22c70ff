#include "ipm_road_mapper/core/geometry/road_surface.h"

#include <limits>

namespace ipm_road_mapper {

RoadSurfaceEstimate RoadSurfaceNear(const std::vector<Eigen::Isometry3d>& T_map_base,
                                    const Eigen::Vector3d& p_map, double radius_m) {
  RoadSurfaceEstimate estimate;
  double closest = std::numeric_limits<double>::infinity();
  std::size_t closest_index = 0;
  Eigen::Vector3d origin_sum = Eigen::Vector3d::Zero(), normal_sum = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < T_map_base.size(); ++i) {
    const double d = (T_map_base[i].translation() - p_map).head<2>().norm();
    if (d < closest) {
      closest = d;
      closest_index = i;
    }
    if (d <= radius_m) {
      origin_sum += T_map_base[i].translation();
      normal_sum += T_map_base[i].linear().col(2);
      ++estimate.frames;
    }
  }
  if (T_map_base.empty()) return estimate;
  estimate.distance_m = closest;
  if (estimate.frames == 0) {
    estimate.frames = 1;
    origin_sum = T_map_base[closest_index].translation();
    normal_sum = T_map_base[closest_index].linear().col(2);
  } else {
    origin_sum /= estimate.frames;
  }
  estimate.plane.point = origin_sum;
  estimate.plane.normal = normal_sum.normalized();
  if (estimate.plane.normal.z() < 0.0) estimate.plane.normal = -estimate.plane.normal;
  return estimate;
}

}  // namespace ipm_road_mapper
