// Internal to instance extraction: the run-length view of an instance mask that the single
// scan produces, and the per-instance geometry computed from an instance's runs. Working on
// runs keeps every step proportional to the instance's own pixels (never to its bounding
// box or the image), so a pathological mask costs at most a few passes over its pixels.
// Not installed; include only from src/core.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "ipm_road_mapper/core/frontend/instance_extraction.h"

namespace ipm_road_mapper {
namespace extraction {

// Largest mask side the run encoding holds (16-bit rows and columns keep a run at 8 bytes:
// an adversarial mask of 1280x720 single-pixel runs then needs 7 MB, not 15).
constexpr int kMaxMaskSide = 65535;

// One horizontal run of equal foreground pixels: columns first_col..last_col of `row`.
struct Run {
  std::uint16_t row = 0;
  std::uint16_t first_col = 0;
  std::uint16_t last_col = 0;
  std::uint16_t slot = 0;  // index of the run's instance in MaskRuns::instances (< 64536)
};

// What the scan learns about one instance value: size and bounding box (pixels).
struct InstanceStats {
  int value = 0;
  int pixel_count = 0;
  int run_count = 0;
  int min_col = 0;
  int max_col = 0;
  int min_row = 0;
  int max_row = 0;
};

// Result of the single scan: instances in order of first appearance, runs row-major.
struct MaskRuns {
  std::vector<InstanceStats> instances;
  std::vector<Run> runs;
};

// One pass over a CV_16UC1 mask: every run of foreground pixels (value >= kInstanceIdFactor)
// and the per-value statistics.
MaskRuns ScanMask(const cv::Mat& mask);

// Why the geometry of one instance was rejected.
enum class GeometryOutcome {
  kOk,
  kRange,
  kDegenerate,
  kOversized,
  kTooWide,
  kTruncated,
  kDoublesBack
};

// Marking rectangle from the runs of one instance `value` of `mask` (row-major). The
// outline is the sub-pixel convex outline of the instance's significant 8-connected pieces
// (all glyphs of a text marking; specks below a tenth of the largest piece are debris); its
// edges along the image border or next to another instance's pixels are cut
// (marking_outline.h), and it is clipped to where the IPM maps (nothing maps: kRange). Then
// the rectangle along base_link's x axis is set (SetMarkingRectangle) and its sides labeled
// measured or cut; kTruncated when fewer than two sides are measured. The rectangle's center also
// gets the x-y block of Omega_p at its pixel (center_cov_base). kOversized when the outline's
// minimum-area ground rectangle is longer than its class's max_length_m or wider than its
// max_width_m. `value`'s class must be in `classes`.
GeometryOutcome ExtractMarking(const Run* runs, int run_count, const cv::Mat& mask, int value,
                               const ClassTable& classes, const Ipm& ipm,
                               const IpmErrorModel& error_model, const ExtractionOptions& options,
                               MarkingObservation* marking);

// Lane centerline points from the runs of one instance (row-major): every
// options.lane_row_step rows from the bottom row up, the center of each run of that row
// (runs within border_margin_px of the image's left or right side are cut: skipped),
// mapped to the ground with its IPM uncertainty. A run whose ground width (the IPM of its
// two outer pixel edges) exceeds class_info.max_width_m plus the IPM uncertainty at its
// center (sqrt of the score) is no line: it gives no point and is added to
// *runs_too_wide; checked before the side cut, since a cut run is at least that wide.
// Rows that cross the instance more than once (two dashes of a curve in one row, a hole,
// a fork) are added to *rows_doubled; kDoublesBack when they are more than a quarter of the
// sampled rows: the instance is two lines (or one turned back on itself), and which of them
// is the line is unknown (a point of each would make a zigzag of both).
// kTooWide when more than half of the runs measured are too wide; kDegenerate when fewer
// than options.min_lane_points survive the IPM.
GeometryOutcome ExtractLane(const Run* runs, int run_count, const ClassInfo& class_info,
                            const Ipm& ipm, const IpmErrorModel& error_model,
                            const ExtractionOptions& options, LaneObservation* lane,
                            std::uint64_t* runs_too_wide, std::uint64_t* rows_doubled);

// Ground width (m, x-y in base_link) of a run: the distance between the IPM of its outer
// pixel edges (first_col - 0.5 and last_col + 0.5 on its row); nullopt when an edge does
// not map to the ground.
std::optional<double> RunGroundWidth(const Run& run, const Ipm& ipm);

// True when the outline's minimum-area rectangle on the ground is longer than
// class_info.max_length_m or its shorter side is wider than class_info.max_width_m.
bool IsOversized(const std::vector<Eigen::Vector2d>& outline_base, const ClassInfo& class_info);

// Pixels of columns first_col..last_col of `row` whose ray descends below the horizon (the
// pinhole model, distortion ignored: for a plausibility ratio, not a measurement).
int PixelsBelowHorizon(const Ipm& ipm, int row, int first_col, int last_col);

// True when the runs of the instances `slots` cover more than `max_coverage` of the image's
// pixels below the horizon (false when no pixel is below the horizon).
bool CoversMoreThan(const Ipm& ipm, const MaskRuns& scan, const std::vector<int>& slots,
                    double max_coverage);

// The rectangle with sides along `axis` (and across it) spanning `outline`,
// counter-clockwise. `outline` must have at least one point, `axis` must not be zero.
std::array<Eigen::Vector2d, 4> BoundingRectangle(const std::vector<Eigen::Vector2d>& outline,
                                                 const Eigen::Vector2d& axis);

// Reorders ground corners canonically: first the corner nearest base_link's origin, then
// counter-clockwise seen from above (positive signed area in x-y).
void OrderCornersCanonically(std::array<Eigen::Vector3d, 4>* corners_base);

}  // namespace extraction
}  // namespace ipm_road_mapper
