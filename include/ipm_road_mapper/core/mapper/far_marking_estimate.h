// The estimate of a marking seen only in far views (MarkingElement::far_only; docs/backend.md,
// "Far views"): flat-ground IPM of a view 25-40 m ahead is meters off along the view where
// the road ahead is not in base_link's plane (a 1 % grade change 16 m before a crossing puts it
// 2.4 m too far from 26 m away), so each view is re-measured on the road's plane at the
// marking, as the vehicle's corrected poses know it.
#pragma once

#include <array>
#include <optional>

#include "ipm_road_mapper/core/geometry/ipm_uncertainty.h"
#include "ipm_road_mapper/core/geometry/pinhole_camera.h"
#include "ipm_road_mapper/core/map/road_map.h"
#include "ipm_road_mapper/core/mapper/map_store.h"

namespace ipm_road_mapper {

// The corners of a far-only element from its views: each view's rectangle re-measured on the
// road plane at the element (MapStore::RoadSurfaceAt: the poses that passed it, or the
// closest one's plane extrapolated; its sides along MapStore::RoadDirectionAt when known),
// seen from the view's corrected pose through T_base_cam; the views averaged with weights
// 1 / tr(Omega_p) of their center pixel (its range error grows as d^2). The plane is looked
// up twice, at the old and the new center. Where no pose has passed yet (farther than the
// store's road_plane_radius_m from every frame), `road_ahead_map` is the plane instead when
// given: the road ahead of the newest pose from its trajectory (trajectory_road_plane.h),
// which does not pitch with the body as the newest pose's own plane does (0.3 deg of
// oscillation is 2.7 m at 30 m). Empty when no view maps onto the plane.
std::optional<std::array<Eigen::Vector3d, 4>> FarOnlyEstimate(
    const PinholeCamera& camera, const Eigen::Isometry3d& T_base_cam,
    const IpmErrorModel& error_model, const MapStore& store, const MarkingElement& element,
    const RoadPlane* road_ahead_map = nullptr);

}  // namespace ipm_road_mapper
