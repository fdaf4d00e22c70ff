// The classes of paint, decided on the ground from the shape and the layout of its pieces:
// lane lines (solid or dashed from the dash pattern along the line), crossing stripes, stop
// lines, arrows and hatched areas. What fits none (a curb, a shadow, a blob of glare) is
// dropped and counted.
#pragma once

#include <string>
#include <vector>

#include "ipm_road_mapper/segmentation/paint_groups.h"

namespace ipm_road_mapper {
namespace segmentation {

enum class PaintClass { kLaneSolid, kLaneDashed, kCrossingStripe, kStopLine, kArrow, kHatchedArea };
constexpr int kPaintClassCount = 6;

// "lane_solid", "lane_dashed", "crossing_stripe", "stop_line", "arrow", "hatched_area".
const char* ToString(PaintClass paint_class);

// The shape rules of the classes (config section `classes`).
struct ClassifyOptions {
  double max_line_width_m = 0.45;  // a line's mean width on the ground, near
  // ... plus this many pixels' ground footprint across the line at its range (the network
  // blurs a line by a few pixels, meters wide far away)
  double line_blur_px = 3.0;
  double min_line_span_m = 1.5;          // shorter lines are left out (too little to fit)
  double max_dash_length_m = 8.0;        // a longer piece is a solid line
  double min_dash_gap_m = 1.5;           // gaps shorter than this are missed paint of one line
  double crossing_max_turn_deg = 20.0;   // crossing stripes lie side by side, this near square
  double crossing_max_spacing_m = 1.6;   // ... and this close (center to center)
  double area_margin_m = 0.5;            // pieces this near a hatched area's stripes join it
  double stop_line_min_turn_deg = 60.0;  // a stop line runs across the travel
  double stop_line_min_length_m = 2.0;
  double stop_line_max_width_m = 0.8;
  double arrow_max_turn_deg = 20.0;  // an arrow points along the travel
  double arrow_min_length_m = 2.5;
  double arrow_max_length_m = 9.0;
  double arrow_max_width_m = 2.5;
  double min_confidence = 0.3;  // instances below are dropped (counted)
};

// The camera's ground resolution: a pixel at range x covers x / focal_px across the view and
// x^2 / (focal_px * height_m) along it.
struct GroundFootprint {
  double focal_px = 1000.0;
  double height_m = 1.5;

  // The ground width of one pixel across a stroke of `direction` centered at `xy`.
  double AcrossStroke(const Eigen::Vector2d& xy, const Eigen::Vector2d& direction) const;
};

// One instance: its class, its pieces and a confidence in [0, 1] (the mean paint
// probability times how clearly its shape says the class).
struct PaintInstance {
  PaintClass paint_class = PaintClass::kLaneSolid;
  std::vector<int> pieces;
  double confidence = 0.0;
};

// What was left out, by reason.
struct ClassifyCounters {
  int blobs = 0;           // no stroke, no arrow: curb, shadow, glare
  int short_lines = 0;     // a line too short to fit
  int wide_strokes = 0;    // a stroke wider than a line that is no stop line
  int low_confidence = 0;  // an instance under min_confidence
};

// Classifies `pieces` (ground base_link; x is the travel direction) into instances: stacks
// of parallel strokes first (crossing stripes when laid side by side square to their
// direction and close, else one hatched area, which takes the pieces among its stripes),
// then chains of the remaining strokes (lines, or a stop line), then the
// blobs (arrows). Every piece ends in at most one instance.
std::vector<PaintInstance> ClassifyPaint(const std::vector<PaintPiece>& pieces,
                                         const GroupOptions& group_options,
                                         const ClassifyOptions& options,
                                         const GroundFootprint& footprint,
                                         ClassifyCounters* counters);

}  // namespace segmentation
}  // namespace ipm_road_mapper
