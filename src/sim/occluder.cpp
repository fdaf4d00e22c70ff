#include "ipm_road_mapper/sim/occluder.h"

#include <cmath>

namespace ipm_road_mapper {
namespace sim {

double OccluderRearS(const OccluderOptions& occluder, double s_cam, double t_s) {
  return s_cam + occluder.gap_m +
         occluder.gap_amplitude_m * std::sin(2.0 * M_PI * t_s / occluder.gap_period_s);
}

std::vector<std::vector<Eigen::Vector3d>> OccluderFaces(const RoadModel& road,
                                                        const OccluderOptions& occluder,
                                                        double s_cam, double t_s) {
  const double s_rear = OccluderRearS(occluder, s_cam, t_s);
  if (s_rear < occluder.start_s_m || s_rear > occluder.end_s_m) return {};
  const double l = occluder.has_offset ? occluder.offset_m : road.LaneCenterOffset(occluder.lane);
  const double s_front = s_rear + occluder.length_m;
  const double half = 0.5 * occluder.width_m;
  // Footprint counter-clockwise from above: rear right, front right, front left, rear left.
  const std::vector<Eigen::Vector3d> bottom = {
      road.SurfacePoint(s_rear, l - half), road.SurfacePoint(s_front, l - half),
      road.SurfacePoint(s_front, l + half), road.SurfacePoint(s_rear, l + half)};
  std::vector<Eigen::Vector3d> top = bottom;
  for (Eigen::Vector3d& p : top) p.z() += occluder.height_m;
  std::vector<std::vector<Eigen::Vector3d>> faces = {bottom, top};
  for (int i = 0; i < 4; ++i) {
    const int j = (i + 1) % 4;
    faces.push_back({bottom[i], bottom[j], top[j], top[i]});
  }
  return faces;
}

}  // namespace sim
}  // namespace ipm_road_mapper
