#include "ipm_road_mapper/core/frontend/frame_registration.h"

#include <cmath>

namespace ipm_road_mapper {

bool NoiseSetsTheGates(const AssociationOptions& options) { return LaneNoiseShare(options) >= 1.0; }

std::vector<int> AssociateMarkingsRegistered(const std::vector<const MarkingElement*>& elements,
                                             const std::vector<MarkingCandidate>& candidates,
                                             const AssociationOptions& options,
                                             const Eigen::Vector2d& heading,
                                             std::optional<double> offset_across_m) {
  if (!offset_across_m || !std::isfinite(*offset_across_m) || !NoiseSetsTheGates(options)) {
    return AssociateMarkings(elements, candidates, options);
  }
  const Eigen::Vector2d shift = *offset_across_m * Eigen::Vector2d(-heading.y(), heading.x());
  std::vector<MarkingCandidate> shifted = candidates;
  for (MarkingCandidate& c : shifted) {
    for (Eigen::Vector3d& corner : c.corners_map) corner.head<2>() += shift;
  }
  return AssociateMarkings(elements, shifted, options);
}

}  // namespace ipm_road_mapper
