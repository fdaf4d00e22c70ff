// Whether the camera could have seen a painted line in the gap between two lane fragments.
// A line that ends leaves a gap the camera looked at and saw empty; a line hidden from the
// view (the inner line of a sharp turn, outside a narrow camera's field of view for tens of
// meters) leaves a gap no frame looked at. The two have the same geometry in the map (the
// same line, 30 m on), so only the frames can tell them apart: a gap longer than
// lanes.join_max_gap_m is bridged only when no frame had a point of it in the image at a
// pixel whose IPM uncertainty would have made it a usable lane point
// (LaneTracker::JoinFragments, docs/backend.md "Joining fragments"), and only when it had
// as much of the gap there as the tracker needs of a line to map it from one frame
// (lanes.min_new_lane_length_m): a sliver of the gap in a corner of one image is no sign the
// line is absent.
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <vector>

#include "ipm_road_mapper/core/geometry/ipm_uncertainty.h"
#include "ipm_road_mapper/core/geometry/pinhole_camera.h"
#include "ipm_road_mapper/core/map/road_map.h"

namespace ipm_road_mapper {

// What makes a gap's point seen in a frame.
struct GapViewOptions {
  // A pixel whose Omega_p score (tr, m^2) is above this gives no usable lane point
  // (association.lane_max_point_score_m2): a line there would not have been mapped.
  double max_point_score_m2 = 1.0;
  double max_range_m = 40.0;      // ipm.max_range_m: farther ground points are rejected
  double border_margin_px = 0.0;  // extraction.border_margin_px
  // A frame saw the gap when the part of it it had in view (as above) spans at least this
  // (lanes.min_new_lane_length_m: a shorter piece of a line starts no lane); 0: any point.
  double min_seen_length_m = 0.0;
  // How far across the gap the line may lie from the given points (the bridge's lateral
  // uncertainty): a point counts as in view only when it is in view displaced this far to
  // either side as well. Near the image's edge a bridge 0.5 m inside a line that lies just
  // outside the view is "in view" while the line is not (urban seeds 2 and 4).
  double lateral_uncertainty_m = 0.0;
  // At most this many frames are checked, evenly strided (a standstill's frames are alike).
  std::size_t max_frames = 400;
};

// The camera the frames were seen with; without one (width 0) every gap counts as seen.
struct GapCamera {
  PinholeCamera camera;
  Eigen::Isometry3d T_base_cam = Eigen::Isometry3d::Identity();
  IpmErrorModel error_model;
};

// The frames [from, to) to look at for the gap between a lane whose last observation is in
// frame `first_last_frame` and one whose first is in `second_first_frame`: those between,
// and those of `lookaround_m` of travel before and after (a straight gap is in view ahead
// of the first's end before its last frame). Clamped to the frames there are.
struct FrameSpan {
  std::size_t from = 0, to = 0;
};
FrameSpan GapFrameSpan(const std::vector<FrameRecord>& frames, std::size_t first_last_frame,
                       std::size_t second_first_frame, double lookaround_m);

// The spacing at which FramesThatSawGap samples the gap's polyline.
constexpr double kGapSampleSpacingM = 0.5;

// How many frames of `span` had a stretch of at least min_seen_length_m of the polyline
// `gap_points_map` (sampled every kGapSampleSpacingM) in view: in front of the camera, in the
// image at least border_margin_px inside (also when moved lateral_uncertainty_m across the
// polyline either way), within max_range_m of base_link, Omega_p score at most
// max_point_score_m2; with the frames' corrected poses. A stretch's length is the
// largest distance of a seen sample from the first seen one, as the tracker measures a new
// line's (its seen samples need not be contiguous: an occluder may cut a seen line).
std::size_t FramesThatSawGap(const std::vector<Eigen::Vector3d>& gap_points_map,
                             const std::vector<FrameRecord>& frames, const FrameSpan& span,
                             const GapCamera& camera, const GapViewOptions& options);

}  // namespace ipm_road_mapper
