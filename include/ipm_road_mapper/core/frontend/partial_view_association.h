// The association cost of a partial view (a marking cut by the border, the near clip or an
// occluder) with an element: by its measured sides, not its center. A partial view's center
// is the center of what the view showed; along a cut direction it can lie meters from the
// element's (a stop line wider than the view seen 6 m ahead: 1.8 m), while its measured
// sides are where the element's are.
#pragma once

#include <Eigen/Core>
#include <array>

#include "ipm_road_mapper/core/frontend/association.h"
#include "ipm_road_mapper/core/map/road_map.h"

namespace ipm_road_mapper {

// Squared Mahalanobis distance of a partial view from an element (to compare with the
// association's gate), negative when their extents do not overlap. The view's sides are paired with
// the element's by direction. Each side the view measured is compared with the element's side along
// that side's normal, under the variance of both Omega_p along it plus the floor
// (MarkingFloorSigma): a measured side of the element must be there, an unmeasured one (a lower
// bound: where the views ended) at most that far inside. The cost is the worst such side's. Along
// the directions the view cut, its extent must overlap the element's (within the same gate): it
// showed a part of it.
double PartialViewCost(const MarkingElement& element, const MarkingCandidate& candidate,
                       const AssociationOptions& options);

}  // namespace ipm_road_mapper
