// Joining the fragments of one painted line: lane A's end and lane B's start, when B
// continues A. Each end is modelled by the data that shaped it (the selected points of the
// observations near it, each frame weighted once): a lateral offset y(x) = a + b x + c x^2
// in a frame along the pair's mean direction, by weighted least squares with a weak
// curvature prior, and its covariance from the lane noise floor and each observation's
// lateral IPM uncertainty (Omega_p, correlated over consecutive frames). The two models are
// compared where the gap is (its middle): the lateral offset and the direction must agree
// within their combined uncertainty (the extrapolation over the gap is in it), the gap must
// be short, the class the same, and the two never seen side by side in one frame (two
// instances of one frame side by side are two lines: the double line's halves 0.2-0.5 m
// apart stay apart; end to end they are one line an occluder split, CoObserved).
#pragma once

#include <optional>
#include <vector>

#include "ipm_road_mapper/core/frontend/association.h"
#include "ipm_road_mapper/core/map/road_map.h"

namespace ipm_road_mapper {

// Gates of the join (config section `lanes`, keys join_*).
struct LaneJoinOptions {
  // On by default: one spline per painted line. Online, a junction is joined once its data
  // has left the windows (LaneTracker::JoinFragments; docs/backend.md, "Joining fragments").
  bool enabled = true;
  double max_gap_m = 20.0;  // longest gap between A's last data and B's first
  // Longest gap (along the driven path) that is joined when no frame saw it at a usable range
  // and both ends keep one offset from the path (a line hidden from the view,
  // lane_gap_visibility.h, lane_path_bridge.h; LaneTracker::JoinFragments); 0: never.
  double max_hidden_gap_m = 40.0;
  double max_overlap_m = 10.0;  // longest stretch where both have data
  double end_length_m = 20.0;   // each end is modelled by its data within this length
  double gate_sigmas = 3.0;     // offset and direction agreement, in combined sigmas
  // An observation's lateral Omega_p (mostly the body's pitch) enters its end model's sigma
  // times this: the pitch moves the points of about this many consecutive frames together
  // (a 1.1 Hz pitch at 20 Hz: a half period is 9 frames), so a model of N frames knows the
  // line no better than N / this independent frames. 0: the floor sigma alone.
  double ipm_correlation_frames = 10.0;
};

// Whether `first`'s end is continued by `second`'s start: the model comparison above. Both
// lanes ordered along the line; `options.lane_position_sigma_m` and the odometry's sigma
// give the per-frame noise floor.
bool LaneContinues(const LaneElement& first, const LaneElement& second, const LaneJoinOptions& join,
                   const AssociationOptions& options);
// The same test as a cost: the larger of the offset's and the direction's disagreement in
// combined sigmas (<= gate_sigmas), or -1 when `second` does not continue `first`. Of
// several candidates the lowest cost is the continuation (at 0.5 m of odometry noise the
// next lane's line 3.5 m beside can pass the gate too). With `co_observed`, also whether the
// two were seen as two lines in one frame (CoObserved, the first test).
double LaneJoinCost(const LaneElement& first, const LaneElement& second,
                    const LaneJoinOptions& join, const AssociationOptions& options,
                    bool* co_observed = nullptr);

// `first` and `second` joined into one lane (first's id and control-point indices at its
// start): first's control points up to its last data, a bridge over the gap on the blend of
// the two end models every `chord_spacing_m`, then second's control points from its first
// data; histories merged by frame. Nullopt when the result would be degenerate.
std::optional<LaneElement> JoinLanes(const LaneElement& first, const LaneElement& second,
                                     const LaneJoinOptions& join, const AssociationOptions& options,
                                     double chord_spacing_m);

// `first` and `second` joined through `bridge_map` (points from first's end to second's
// start, e.g. BridgeAlongPath): first's control points but its last `first_end_dropped` real
// ones, the bridge, second's but its first `second_start_dropped`; the rest as JoinLanes.
// Nullopt when either lane would keep fewer than 2 real control points.
std::optional<LaneElement> JoinLanesThrough(const LaneElement& first, const LaneElement& second,
                                            const std::vector<Eigen::Vector3d>& bridge_map,
                                            std::size_t first_end_dropped = 0,
                                            std::size_t second_start_dropped = 0);

// Horizontal direction of a lane at its end (at_end) or start, pointing along the lane,
// from its last (first) interior control point to the one about `length_m` before (after)
// it (0: the adjacent one); zero when degenerate.
Eigen::Vector2d LaneEndDirection(const std::vector<Eigen::Vector3d>& control_points_map,
                                 bool at_end, double length_m);

// `other`'s observations merged into `lane`: histories by frame, pruned counts, the frame and
// stamp spans (a merge or a join; control points are the caller's).
void MergeObservations(const LaneElement& other, LaneElement* lane);

// Whether the two lanes were seen as two lines in one frame: a frame with a measurement of
// each (histories sorted by frame) whose selected points overlap along the line (the mean of
// the two sets' principal directions) by more than kSideBySideOverlapM, or whose means lie
// more than kCollinearOffsetM apart across it, or either without extent. Two instances of
// one frame side by side are two lines (a double line's halves), as are two staggered ones;
// end to end on one line they are one line whose instance an occluder split (a vehicle on it).
constexpr double kSideBySideOverlapM = 0.5;
constexpr double kCollinearOffsetM = 0.5;
bool CoObserved(const LaneElement& a, const LaneElement& b);

}  // namespace ipm_road_mapper
