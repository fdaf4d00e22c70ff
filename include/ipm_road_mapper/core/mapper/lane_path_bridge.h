// A painted line across a gap no frame saw, laid along the driven path. Over a hidden gap (the
// inner line of a sharp turn, outside a narrow camera's view for 30-40 m) the two end models
// of lane_join.h extrapolate too far to agree: the line turns 60 deg and more there, more than
// a parabola in one frame holds. The vehicle drove that gap, though, and a road's lines run
// along its road: the line keeps its lateral offset from the path. So each end is placed on
// the path of the frames around the gap (arc length s, signed offset o, left positive), the
// pair is one line when the second lies ahead along the path within the gap bound, both ends
// run along the path (within 30 deg, the join's direction test) and their offsets agree
// (LaneTracker::JoinCost's gate), and the bridge is the path offset by o blended from the
// first's to the second's (z linear between the ends). An end's offset is the median over
// its control points of its last `end_length_m` (lanes.join_end_length_m), not its last
// control point alone, which the fewest points shaped; the end's control points that lie off
// that offset by more than `max_end_deviation_m` (the line curving out of the view at the
// image's edge, the end grown from a few points) are replaced by the bridge, two kept at
// least. The gap's bound and the direction test apply to the kept ends.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "ipm_road_mapper/core/map/road_map.h"
#include "ipm_road_mapper/core/mapper/lane_gap_visibility.h"

namespace ipm_road_mapper {

struct PathBridge {
  // Every `spacing_m` along the path over the gap, `inset_m` clear of either end.
  std::vector<Eigen::Vector3d> points;
  // Those of them between where the two lanes' data ended (the bridge also replaces the
  // dropped control points below, which had data): the gap no frame may have seen.
  std::vector<Eigen::Vector3d> unseen_points;
  double gap_m = 0.0;            // along the path, from the first's end to the second's start
  double offset_change_m = 0.0;  // the second's offset from the path minus the first's
  // Control points at the first's end and the second's start that lie off their end's offset
  // by more than max_end_deviation_m: the bridge replaces them (JoinLanesThrough).
  std::size_t first_end_dropped = 0;
  std::size_t second_start_dropped = 0;
};

// The bridge from `first`'s end to `second`'s start along the path of frames[span], or
// nullopt when the ends do not both lie beside that path with the second ahead, within
// `max_gap_m`, both along the path.
std::optional<PathBridge> BridgeAlongPath(const LaneElement& first, const LaneElement& second,
                                          const std::vector<FrameRecord>& frames,
                                          const FrameSpan& span, double max_gap_m, double spacing_m,
                                          double inset_m, double end_length_m,
                                          double max_end_deviation_m);

}  // namespace ipm_road_mapper
