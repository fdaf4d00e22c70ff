// Instance extraction: 16UC1 instance mask -> marking rectangles and lane centerline points
// on the ground of base_link (docs/design.md §2 encoding, §4 markings).
#pragma once

#include <opencv2/core.hpp>
#include <string>

#include "ipm_road_mapper/core/frontend/class_table.h"
#include "ipm_road_mapper/core/frontend/observations.h"
#include "ipm_road_mapper/core/geometry/ipm.h"
#include "ipm_road_mapper/core/geometry/ipm_uncertainty.h"
#include "ipm_road_mapper/core/io/yaml_options.h"

namespace ipm_road_mapper {

// Tuning of the extraction (config section `extraction`).
struct ExtractionOptions {
  int min_marking_pixels = 150;       // smaller marking instances are dropped (tiny)
  int min_lane_pixels = 80;           // smaller lane instances are dropped (tiny)
  int border_margin_px = 2;           // outline edges this close to the border are cut there
  int lane_row_step = 4;              // take a lane centerline point every this many rows
  int min_lane_points = 4;            // fewer valid centerline points: degenerate
  int max_instances_per_frame = 300;  // beyond this, the remaining instances are dropped
  double max_marking_range_m = 25.0;  // marking whose ground center is farther: a far view
  // Far views (center beyond max_marking_range_m, up to this range) are kept when they show
  // the whole marking: they map a marking no nearer view shows, never one a nearer view
  // does, and never enter the back end (MarkingTracker). 0: none (dropped as out of range).
  double far_marking_range_m = 0.0;
  double min_rectangle_side_m = 0.05;  // thinner ground rectangles are degenerate
  // A frame with more candidate instances than this (known class, not tiny)
  // is no real segmentation: its observations are dropped (the pose is still used).
  int max_plausible_instances = 100;
  // Same when the candidates' pixels cover more than this fraction of the pixels below
  // the horizon (a network gone wrong paints the whole road).
  double max_coverage = 0.5;
};

// Reads the `extraction` section; throws OptionsError naming the bad key.
ExtractionOptions LoadExtractionOptions(OptionsReader reader);

// Checks a mask before extraction: CV_16UC1 and the camera's size. Empty when usable,
// otherwise the reason (e.g. "mask is 640x480, camera is 1280x720").
std::string ValidateMask(const cv::Mat& mask, int expected_width, int expected_height);

// Sets the marking's rectangle from its outline with sides along `axis_base` (the road's
// direction in base_link, x-y): corners on the ground in canonical order, their pixels, the
// center and its Omega_p, and the sides' labels (measured or cut, from the outline's cut
// edges; side_uv). The minimum-area rectangle is no substitute: for an arrow it can
// lie along a slanted edge of the head, 0.3-0.4 m off at the corners and inconsistent from
// frame to frame. False when a corner does not project.
bool SetMarkingRectangle(const Ipm& ipm, const IpmErrorModel& error_model,
                         const Eigen::Vector2d& axis_base, MarkingObservation* marking);

// Extracts every instance of `mask` (which must pass ValidateMask; an unusable mask gives
// nothing). One scan groups the pixels by value; unknown classes and tiny instances are
// dropped from its statistics; when the rest are more than max_plausible_instances or cover
// more than max_coverage of the pixels below the horizon, the frame gives no observation
// (counted); otherwise the max_instances_per_frame largest are processed. Markings: sub-pixel
// outline of the significant 8-connected pieces (every glyph of a text; specks under a tenth
// of the largest piece are left out), its edges along the image border or next to another
// instance labeled cut, clipped to where the IPM maps -> the rectangle along base_link's x
// axis (SetMarkingRectangle) -> canonical corners, projected back for the pixel
// measurements, each side labeled measured or cut (a partial view; every side cut:
// dropped_border); a rectangle (minimum-area, on the ground) longer or wider than the
// class's max_length_m / max_width_m is dropped (oversized).
// Lanes: every lane_row_step rows from the bottom, the center column of each run of the
// instance's pixels in that row -> IPM point + uncertainty score; a run wider on the ground
// than the class's max_width_m plus the IPM uncertainty gives no point, and an instance with
// most runs too wide is dropped (wide). Results sorted by value.
FrameObservations ExtractObservations(const cv::Mat& mask, const ClassTable& classes,
                                      const Ipm& ipm, const IpmErrorModel& error_model,
                                      const ExtractionOptions& options);

}  // namespace ipm_road_mapper
