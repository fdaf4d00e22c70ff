// The unmeasured sides of a marking seen only in partial views, measured again at the end of
// the drive on the road plane from the corrected poses (docs/backend.md, "Partial views").
//
// While driving, an unmeasured side is the union of where the views ended (marking_extent.h),
// each view's outline mapped by flat-ground IPM onto its own base_link plane, which pitches
// with the body: 0.3 deg of pitch puts a view's end 0.9 m along the road at 17 m, and the
// union keeps the farthest of them. Here every view's outline is re-intersected with the road
// plane at the marking (MapStore::RoadSurfaceAt) from its corrected pose, where the body's
// pitch drops out, and each unmeasured side is the union again: the largest extent of any
// view's outline along that side's outward normal. Measured sides are left as they are.
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <optional>

#include "ipm_road_mapper/core/geometry/pinhole_camera.h"
#include "ipm_road_mapper/core/map/road_map.h"
#include "ipm_road_mapper/core/mapper/map_store.h"

namespace ipm_road_mapper {

// The element's corners with each unmeasured side moved (both of its corners, along its
// outward normal in x-y) to the union of its views on the road plane. Empty when there is
// nothing to do: a complete element, one whose history was pruned (views missing: their
// union is not known), or no view whose outline maps onto the plane.
std::optional<std::array<Eigen::Vector3d, 4>> PartialExtentOnRoad(
    const PinholeCamera& camera, const Eigen::Isometry3d& T_base_cam, const MapStore& store,
    const MarkingElement& element);

}  // namespace ipm_road_mapper
