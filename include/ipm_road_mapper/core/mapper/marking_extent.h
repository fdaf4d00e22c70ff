// The extent of a marking element seen in partial views (docs/backend.md, "Partial views"):
// which of an observation's corners are the element's, and how the element's sides move
// with each view. A measured side is a running mean of its measured positions; a side no
// view has measured yet is where the views ended so far, and grows outwards (the union of
// the views along that direction) as later views show more of the marking.
#pragma once

#include <Eigen/Core>
#include <array>

#include "ipm_road_mapper/core/map/road_map.h"

namespace ipm_road_mapper {

// The cyclic shift k for which the observation's side (i + k) % 4 runs in the direction of
// the element's side i (sides from corner i to i + 1): unlike the nearest-corner match it
// holds for a view that shows only part of the element.
int SideAlignedShift(const std::array<Eigen::Vector3d, 4>& element_corners_map,
                     const std::array<Eigen::Vector3d, 4>& observation_corners_map);

// Moves the element's sides by one observation (corners in the map and side flags, both
// already in the element's order): a side the observation measured joins the running mean
// of its measured positions (or replaces the lower bound of an unmeasured one); a cut side
// of the observation extends an unmeasured side of the element outwards, never inwards.
// With `owned` (the back end owns the estimate) only unmeasured sides move. Each side moves
// both of its corners along the side's outward normal (x-y), so the shape is kept.
void UpdateExtent(const std::array<Eigen::Vector3d, 4>& observation_corners_map,
                  const std::array<bool, 4>& observation_sides, bool owned,
                  MarkingElement* element);

}  // namespace ipm_road_mapper
