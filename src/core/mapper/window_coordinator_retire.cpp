// Retirement of a marking that leaves the window: its information about the extrinsic moves
// into the extrinsic prior, its corners marginalized.
#include <algorithm>

#include "ipm_road_mapper/core/backend/extrinsic_marginalization.h"
#include "ipm_road_mapper/core/frontend/marking_measurement.h"
#include "ipm_road_mapper/core/mapper/window_coordinator.h"

namespace ipm_road_mapper {

void WindowCoordinator::RetireMarking(MarkingElement* marking) {
  marking->retired = true;
  if (!options_.backend.optimize_extrinsic || !options_.backend.optimize_markings) return;
  const PinholeCamera camera(camera_);
  MarginalizationInput input;
  input.points.assign(marking->corners_map.begin(), marking->corners_map.end());
  // Corners re-measured on the road plane where the vehicle passed the marking.
  const RoadSurfaceEstimate road = store_->RoadSurfaceAt(marking->Center());
  const RoadPlane& plane = road.plane;
  const Eigen::Vector3d axis = store_->RoadDirectionAt(marking->Center());
  // As in the window problem: partial views only for a marking no whole view shows.
  const bool seen_whole = std::any_of(marking->history.begin(), marking->history.end(),
                                      [](const MarkingMeasurement& m) { return m.Complete(); });
  for (const MarkingMeasurement& m : marking->history) {
    if (seen_whole && !m.Complete()) continue;
    const Eigen::Isometry3d& T_map_base = store_->frames()[m.frame_index].T_map_base;
    std::array<Eigen::Vector2d, 4> corners_uv = m.corners_uv;
    if (axis.norm() > 0.0 && !m.outline_uv.empty()) {
      std::array<Eigen::Vector2d, 4> on_plane;
      if (MeasureCornersOnPlane(camera, T_map_base * T_base_cam_, plane, axis, marking->corners_map,
                                m.outline_uv, &on_plane)) {
        corners_uv = on_plane;
      }
    }
    for (int c = 0; c < 4; ++c) {
      // Only corners the view measured (a partial view's cut corners are where it ended).
      if (!m.CornerMeasured(c) || !corners_uv[c].allFinite()) continue;
      input.corners.push_back({c, corners_uv[c], T_map_base});
    }
  }
  if (options_.backend.optimize_z) {
    for (int c = 0; c < 4; ++c) {
      const RoadSurfaceEstimate at = store_->RoadSurfaceAt(marking->corners_map[c]);
      input.road_priors.push_back({c, at.plane, RoadPriorSigma(at)});
    }
  }
  extrinsic_prior_.Add(MarginalizeIntoExtrinsic(camera, extrinsic_prior_, T_base_cam_, input,
                                                options_.backend.pixel_sigma_px,
                                                options_.backend.robust_scale));
}

}  // namespace ipm_road_mapper
