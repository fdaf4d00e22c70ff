// Data association of one frame's observations with the map's elements: gated and
// class-aware, one-to-one within a frame (greedy by increasing cost).
//  - markings: center distance within a gate, then the best cyclic order of the corners;
//  - lanes: lateral distance of the observation's points to the element's spline (or to
//    its end tangent, for points just past an end) and direction agreement.
#pragma once

#include <Eigen/Core>
#include <array>
#include <vector>

#include "ipm_road_mapper/core/road_map.h"
#include "ipm_road_mapper/core/yaml_options.h"

namespace ipm_road_mapper {

// Gates of the association (config section `association`).
struct AssociationOptions {
  double marking_gate_m = 1.5;        // max center distance between observation and element
  double lane_gate_m = 0.8;           // max median lateral distance to the lane
  double lane_min_direction_cos = 0.9;  // min |cos| between observation and lane directions
  double lane_max_end_gap_m = 15.0;   // points this far past a lane end still count (growth)
  double lane_min_support = 0.3;      // fraction of the observation's points that must count
  int spurious_after_frames = 10;     // element seen once, unseen for this many frames: dropped
};

// Reads the `association` section; throws OptionsError naming the bad key.
AssociationOptions LoadAssociationOptions(OptionsReader reader);

// The cyclic shift s minimizing sum_i |element[i] - observation[(i + s) % 4]|; writes the
// mean corner distance of that order to *mean_distance_m.
int BestCyclicShift(const std::array<Eigen::Vector3d, 4>& element,
                    const std::array<Eigen::Vector3d, 4>& observation, double* mean_distance_m);

// A marking observation in the map frame, for association.
struct MarkingCandidate {
  int class_id = 0;
  std::array<Eigen::Vector3d, 4> corners_map;
};

// For each candidate, the index of its marking element or -1 (new element).
std::vector<int> AssociateMarkings(const std::vector<MarkingElement>& elements,
                                   const std::vector<MarkingCandidate>& candidates,
                                   const AssociationOptions& options);

// A lane observation in the map frame, for association.
struct LaneCandidate {
  int class_id = 0;
  std::vector<Eigen::Vector3d> points_map;  // ordered along the lane
};

// Cost of explaining `candidate` by `lane` (median lateral distance, m); negative when the
// lane is not a candidate (class, direction, support or gate fail).
double LaneAssociationCost(const LaneElement& lane, const LaneCandidate& candidate,
                           const AssociationOptions& options);

// For each candidate, the index of its lane element or -1 (new element).
std::vector<int> AssociateLanes(const std::vector<LaneElement>& lanes,
                                const std::vector<LaneCandidate>& candidates,
                                const AssociationOptions& options);

}  // namespace ipm_road_mapper
