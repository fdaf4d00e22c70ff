#include "ipm_road_mapper/core/mapper/partial_extent_on_road.h"

#include <cmath>
#include <limits>

#include "ipm_road_mapper/core/geometry/road_surface.h"

namespace ipm_road_mapper {

std::optional<std::array<Eigen::Vector3d, 4>> PartialExtentOnRoad(
    const PinholeCamera& camera, const Eigen::Isometry3d& T_base_cam, const MapStore& store,
    const MarkingElement& element) {
  if (element.Complete() || element.far_only || element.pruned > 0) return std::nullopt;
  const Eigen::Vector3d center = element.Center();
  const RoadPlane plane = store.RoadSurfaceAt(center).plane;  // normal up (road_surface.h)
  // Outward normals of the sides (x-y), and the union of the views along each.
  std::array<Eigen::Vector2d, 4> normal;
  std::array<double, 4> reach;
  reach.fill(-std::numeric_limits<double>::infinity());
  for (int s = 0; s < 4; ++s) {
    const Eigen::Vector2d a = element.corners_map[s].head<2>();
    const Eigen::Vector2d b = element.corners_map[(s + 1) % 4].head<2>();
    const Eigen::Vector2d along = (b - a).normalized();
    Eigen::Vector2d out = 0.5 * (a + b) - center.head<2>();
    out -= along * along.dot(out);
    normal[s] = out.norm() > 1e-9 ? Eigen::Vector2d(out.normalized()) : Eigen::Vector2d::Zero();
  }
  bool any = false;
  for (const MarkingMeasurement& meas : element.history) {
    if (meas.frame_index >= store.frames().size() || meas.outline_uv.empty()) continue;
    const Eigen::Isometry3d T_map_cam = store.CorrectedPose(meas.frame_index) * T_base_cam;
    std::array<double, 4> view_reach;
    view_reach.fill(-std::numeric_limits<double>::infinity());
    bool maps = true;
    for (const Eigen::Vector2d& uv : meas.outline_uv) {
      Eigen::Vector3d p_map;
      maps = PixelOntoPlane(camera, T_map_cam, plane, uv, &p_map);
      if (!maps) break;
      const Eigen::Vector2d p = p_map.head<2>() - center.head<2>();
      for (int s = 0; s < 4; ++s) view_reach[s] = std::max(view_reach[s], normal[s].dot(p));
    }
    if (!maps) continue;
    for (int s = 0; s < 4; ++s) reach[s] = std::max(reach[s], view_reach[s]);
    any = true;
  }
  if (!any) return std::nullopt;
  std::array<Eigen::Vector3d, 4> corners = element.corners_map;
  for (int s = 0; s < 4; ++s) {
    if (element.side_measured[s] || normal[s].isZero() || !std::isfinite(reach[s])) continue;
    const Eigen::Vector2d a = element.corners_map[s].head<2>() - center.head<2>();
    const double move = reach[s] - normal[s].dot(a);
    for (int c : {s, (s + 1) % 4}) corners[c].head<2>() += move * normal[s];
  }
  return corners;
}

}  // namespace ipm_road_mapper
