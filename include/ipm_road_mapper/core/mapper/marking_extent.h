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

// The rectangle of a partially seen element after the back end refined its corners. A cut
// corner has no corner residual, only the edge residuals of its measured side, which leave it
// free along that side's line: a solve slid such corners meters inwards and left a
// quadrilateral that is no rectangle (urban's stop line 2.2 m off at its center). The result
// is the rectangle with the refined corners' orientation (their sides, measured ones only
// when there are any, length-weighted), each measured side where the refined corners put
// it, and each unmeasured side where the extent had it before the solve (`before_map`: the
// union of the views). The refined corners' heights are kept.
std::array<Eigen::Vector3d, 4> RectifyPartialExtent(
    const std::array<Eigen::Vector3d, 4>& before_map,
    const std::array<Eigen::Vector3d, 4>& refined_map, const std::array<bool, 4>& side_measured);

}  // namespace ipm_road_mapper
