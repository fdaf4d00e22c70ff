#include "ipm_road_mapper/core/frontend/partial_view_association.h"

#include <algorithm>
#include <cmath>

namespace ipm_road_mapper {
namespace {

// Unit direction (x-y) of side i (corner i to i + 1); zero when degenerate.
Eigen::Vector2d Direction(const std::array<Eigen::Vector3d, 4>& corners, int i) {
  const Eigen::Vector2d d = (corners[(i + 1) % 4] - corners[i]).head<2>();
  return d.norm() > 1e-9 ? Eigen::Vector2d(d.normalized()) : Eigen::Vector2d::Zero();
}

// The shift k for which the candidate's side (i + k) % 4 runs along the element's side i.
int AlignedShift(const std::array<Eigen::Vector3d, 4>& element,
                 const std::array<Eigen::Vector3d, 4>& candidate) {
  int best_shift = 0;
  double best = -1e18;
  for (int shift = 0; shift < 4; ++shift) {
    double agreement = 0.0;
    for (int i = 0; i < 4; ++i) {
      agreement += Direction(element, i).dot(Direction(candidate, (i + shift) % 4));
    }
    if (agreement > best) {
      best = agreement;
      best_shift = shift;
    }
  }
  return best_shift;
}

// Offset of side i along its outward normal n (corners counter-clockwise).
double SideOffset(const std::array<Eigen::Vector3d, 4>& corners, int i, const Eigen::Vector2d& n) {
  return 0.5 * n.dot(corners[i].head<2>() + corners[(i + 1) % 4].head<2>());
}

}  // namespace

double PartialViewCost(const MarkingElement& element, const MarkingCandidate& candidate,
                       const AssociationOptions& options) {
  const int shift = AlignedShift(element.corners_map, candidate.corners_map);
  const double floor = std::pow(MarkingFloorSigma(options), 2);
  const Eigen::Matrix2d S = candidate.center_cov_map + element.center_cov_map;
  const double gate_sigmas = options.marking_gate_sigmas;
  double worst = -1.0;
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector2d along = Direction(element.corners_map, i);
    if (along.squaredNorm() == 0.0) return -1.0;
    const Eigen::Vector2d outward(along.y(), -along.x());
    const double sigma = std::sqrt(outward.dot(S * outward) + floor);
    const int j = (i + shift) % 4;
    // The candidate's side j, along the element's normal: its offset is where its corners are.
    const double element_offset = SideOffset(element.corners_map, i, outward);
    const double candidate_offset = SideOffset(candidate.corners_map, j, outward);
    double d = candidate_offset - element_offset;
    if (candidate.side_measured[j]) {
      if (!element.side_measured[i]) d = std::min(d, 0.0);  // beyond a lower bound: it grows
      worst = std::max(worst, (d / sigma) * (d / sigma));
      continue;
    }
    // A cut side of the view: along this normal its extent must overlap the element's
    // (within the gate): it showed a part of it.
    const double element_low = SideOffset(element.corners_map, (i + 2) % 4, outward);
    const double candidate_low = SideOffset(candidate.corners_map, (j + 2) % 4, outward);
    if (candidate_low > element_offset + gate_sigmas * sigma ||
        candidate_offset < element_low - gate_sigmas * sigma) {
      return -1.0;
    }
  }
  return worst;
}

}  // namespace ipm_road_mapper
