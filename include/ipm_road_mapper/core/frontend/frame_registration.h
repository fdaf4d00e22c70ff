// Association of a frame's markings in the frame registered to the map across the road.
//
// Every observation of one frame carries that frame's pose error: at 0.5 m of per-pose
// odometry noise a whole crossing's stripes, 1 m apart, arrive shifted together by up to a
// meter. Associated one by one within a gate that must admit that error (3 floor sigmas:
// 2.25 m at the told 0.75 m), each stripe is about as close to its neighbour's element as to
// its own, and the greedy assignment mixed them: on public_road at 0.5 m noise the mapped
// stripes were 0.51 m off on average, the other markings 0.15 m.
//
// So the candidates are first moved across the frame's heading by the offset that puts the
// same frame's lane observations on the lanes they continue (LaneTracker::OffsetAcross),
// then associated. The lanes measure it, not the markings: a crossing is periodic across the
// road, and a first association that took each stripe's neighbour gives a consistent, wrong
// offset; lane lines 3.5 m apart are not ambiguous at that error. Along the heading nothing
// is registered: the markings' along offsets are dominated by the IPM's range error (a pitch
// error moves a marking 20 m ahead by about a meter), not by the frame's pose (public_road:
// the median along offset of a frame's markings reached 4.7 m).
//
// Only where the odometry's noise sets the gates (NoiseSetsTheGates): at the default noise
// the lanes' own IPM error is as large as the pose error it would remove, and measured
// there it moved public_road's calibration into its other basin (rotation 0.031 -> 0.269
// deg). The shift is only for association: what is recorded and fitted stays at the frame's
// pose, which the back end corrects.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "ipm_road_mapper/core/frontend/association.h"

namespace ipm_road_mapper {

// Whether the odometry's noise sets the lane gate (LaneNoiseShare 1: 3 floor sigmas at
// least lane_gate_m, about 0.4 m of per-pose noise and more).
bool NoiseSetsTheGates(const AssociationOptions& options);

// AssociateMarkings with the candidates moved by `offset_across_m` to the left of `heading`
// (unit, x-y), when it is given and finite and NoiseSetsTheGates(options); otherwise
// AssociateMarkings itself. The result indexes `elements` as AssociateMarkings' does.
std::vector<int> AssociateMarkingsRegistered(const std::vector<const MarkingElement*>& elements,
                                             const std::vector<MarkingCandidate>& candidates,
                                             const AssociationOptions& options,
                                             const Eigen::Vector2d& heading,
                                             std::optional<double> offset_across_m);

}  // namespace ipm_road_mapper
