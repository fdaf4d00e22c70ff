#include "ipm_road_mapper/core/mapper/far_marking_estimate.h"

#include <cmath>

#include "ipm_road_mapper/core/frontend/marking_measurement.h"
#include "ipm_road_mapper/core/geometry/ipm.h"

namespace ipm_road_mapper {
namespace {

// Passes over the views: the plane is looked up at the old center, then at the new one.
constexpr int kPlaneLookups = 2;

}  // namespace

std::optional<std::array<Eigen::Vector3d, 4>> FarOnlyEstimate(const PinholeCamera& camera,
                                                              const Eigen::Isometry3d& T_base_cam,
                                                              const IpmErrorModel& error_model,
                                                              const MapStore& store,
                                                              const MarkingElement& element,
                                                              const RoadPlane* road_ahead_map) {
  std::array<Eigen::Vector3d, 4> corners = element.corners_map;
  bool any = false;
  for (int pass = 0; pass < kPlaneLookups; ++pass) {
    const Eigen::Vector3d center = 0.25 * (corners[0] + corners[1] + corners[2] + corners[3]);
    const RoadSurfaceEstimate surface = store.RoadSurfaceAt(center);
    const bool passed = surface.distance_m <= store.road_plane_radius_m();
    const RoadPlane plane = passed || !road_ahead_map ? surface.plane : *road_ahead_map;
    const Eigen::Vector3d axis = store.RoadDirectionAt(center);
    std::array<Eigen::Vector3d, 4> sum;
    sum.fill(Eigen::Vector3d::Zero());
    double weight_sum = 0.0;
    for (const MarkingMeasurement& meas : element.history) {
      if (meas.frame_index >= store.frames().size()) continue;
      const Eigen::Isometry3d T_map_cam = store.CorrectedPose(meas.frame_index) * T_base_cam;
      std::array<Eigen::Vector2d, 4> corners_uv = meas.corners_uv;
      if (axis.norm() > 0.0 && !meas.outline_uv.empty()) {
        std::array<Eigen::Vector2d, 4> on_plane;
        if (MeasureCornersOnPlane(camera, T_map_cam, plane, axis, corners, meas.outline_uv,
                                  &on_plane)) {
          corners_uv = on_plane;
        }
      }
      std::array<Eigen::Vector3d, 4> view;
      bool maps = true;
      for (int c = 0; c < 4 && maps; ++c)
        maps = PixelOntoPlane(camera, T_map_cam, plane, corners_uv[c], &view[c]);
      if (!maps) continue;
      const Eigen::Vector2d center_uv =
          0.25 * (corners_uv[0] + corners_uv[1] + corners_uv[2] + corners_uv[3]);
      const std::optional<IpmUncertainty> uncertainty =
          ComputeIpmUncertainty(camera, T_base_cam, center_uv, error_model);
      if (!uncertainty) continue;
      const double weight = 1.0 / std::max(uncertainty->omega.topLeftCorner<2, 2>().trace(), 1e-6);
      for (int c = 0; c < 4; ++c) sum[c] += weight * view[c];
      weight_sum += weight;
    }
    if (!(weight_sum > 0.0)) break;
    for (int c = 0; c < 4; ++c) corners[c] = sum[c] / weight_sum;
    any = true;
  }
  if (!any) return std::nullopt;
  return corners;
}

}  // namespace ipm_road_mapper
