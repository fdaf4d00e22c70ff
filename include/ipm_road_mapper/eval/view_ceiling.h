// The view's ceiling: what a map of exactly the road the camera saw would score on a drive,
// from the ground truth alone (true poses, true extrinsic, the camera), never from a map.
//
// A GT point is *in view* when some frame's camera images it (in front of the camera, inside
// the image) and it lies within view_range_m of that frame's base_link, horizontally (the
// mapper's ipm.max_range_m: it maps no ground farther). Vehicles hiding the road are not
// modelled, so every figure is an upper bound of what a map can reach.
// - A GT lane is *reachable* when at least lane_match_fraction of its points are in view:
//   the share of a GT lane a map can cover is at most its share in view, and the lane F1
//   matches a GT lane covered for lane_match_fraction (EvaluateLanes).
// - A GT marking is *reachable* when the rectangle of its in-view part, in the marking's own
//   axes, has its center within marking_gate_m of the marking's: a map that records what was
//   seen and guesses no unseen end (the mapper's partial elements, `complete: false`) can
//   put it there at best. Its in-view part is sampled on a grid every
//   view_marking_sample_spacing_m (coarser beyond 1e5 samples); a GT marking with a corner
//   more than 200 m from its center is not looked for (unreachable).
// The recall ceilings count reachable GT lanes over all GT lanes, reachable GT markings over
// the GT markings the drive's masks hold (visible_frames > 0), as EvaluateLanes and
// EvaluateMarkings count recall; the F1 ceiling takes precision 1.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "ipm_road_mapper/core/io/ground_truth.h"
#include "ipm_road_mapper/core/map/vector_map.h"

namespace ipm_road_mapper {

struct EvaluationOptions;

struct ViewCeilingLane {
  int gt_id = 0;
  double in_view_fraction = 0.0;  // share of its points in view
  bool reachable = false;         // in_view_fraction >= lane_match_fraction
};

struct ViewCeilingMarking {
  int gt_id = 0;
  int visible_frames = 0;         // the GT's own count (frames whose mask holds it)
  double in_view_fraction = 0.0;  // share of its samples in view
  // Center of the in-view part's rectangle, and its distance to the marking's center; NaN
  // when no sample is in view.
  Eigen::Vector3d in_view_center_map = Eigen::Vector3d::Zero();
  double in_view_center_offset_m = 0.0;
  bool reachable = false;  // visible_frames > 0 and the offset within marking_gate_m
};

struct ViewCeilingMetrics {
  double view_range_m = 0.0;
  int lanes_total = 0;
  int lanes_reachable = 0;
  double lane_recall = 0.0;  // NaN without GT lanes
  double lane_f1 = 0.0;      // 2 R / (1 + R); NaN without GT lanes
  int markings_visible = 0;  // GT markings with visible_frames > 0
  int markings_reachable = 0;
  double marking_recall = 0.0;  // NaN without visible GT markings
  std::vector<ViewCeilingLane> lanes;
  std::vector<ViewCeilingMarking> markings;
};

// What the map got right of what was seen: each GT marking the masks hold and some frame saw
// is matched, by class and within marking_gate_m, to the map marking nearest the center of
// its in-view part (one-to-one, nearest pairs first, as EvaluateMarkings matches the whole
// markings). A marking seen whole has its own center there; one wider than the view is judged
// by the part a map could know. A diagnostic beside the marking recall and APE, not instead.
struct SeenPartMarking {
  int gt_id = 0;
  bool matched = false;
  std::uint64_t map_id = 0;   // valid when matched
  double center_error_m = 0;  // map center to the in-view part's center; NaN unless matched
};
struct SeenPartMetrics {
  int gt_seen = 0;  // GT markings with visible_frames > 0 and some sample in view
  int matched = 0;
  double recall = 0.0;             // matched / gt_seen; NaN without any
  double center_error_mean_m = 0;  // NaN without a match
  double center_error_max_m = 0;
  std::vector<SeenPartMarking> markings;  // per GT marking counted in gt_seen
};

// The ceiling of `gt`'s drive (see above). Cost: per GT point, the frames within
// view_range_m of it (a grid index over the true positions), stopping at the first that sees
// it.
ViewCeilingMetrics EvaluateViewCeiling(const GroundTruth& gt, const EvaluationOptions& options);

// The map's markings against the in-view parts `ceiling` found for `gt` (SeenPartMetrics).
SeenPartMetrics EvaluateSeenParts(const VectorMap& map, const GroundTruth& gt,
                                  const ViewCeilingMetrics& ceiling,
                                  const EvaluationOptions& options);

}  // namespace ipm_road_mapper
