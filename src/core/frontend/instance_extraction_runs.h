// Internal to instance extraction: the run-length view of an instance mask that the single
// scan produces, and the per-instance geometry computed from an instance's runs. Working on
// runs keeps every step proportional to the instance's own pixels (never to its bounding
// box or the image), so a pathological mask costs at most a few passes over its pixels.
// Not installed; include only from src/core.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
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
enum class GeometryOutcome { kOk, kRange, kDegenerate };

// Marking rectangle from the runs of one instance (row-major). The outline is the sub-pixel
// convex outline of the instance's significant 8-connected pieces (all glyphs of a text
// marking; specks below a tenth of the largest piece are debris). All of its points are
// mapped to the ground (any failure: kRange, the marking is cut by the horizon or
// the IPM range), then the rectangle along base_link's x axis is set (SetMarkingRectangle).
// The rectangle's center also gets the x-y block of Omega_p at its pixel (center_cov_base).
GeometryOutcome ExtractMarking(const Run* runs, int run_count, const Ipm& ipm,
                               const IpmErrorModel& error_model, const ExtractionOptions& options,
                               MarkingObservation* marking);

// Lane centerline points from the runs of one instance (row-major): every
// options.lane_row_step rows from the bottom row up, the center of each run of that row
// (runs within border_margin_px of the image's left or right side are cut: skipped),
// mapped to the ground with its IPM uncertainty. kDegenerate when fewer than
// options.min_lane_points survive the IPM.
GeometryOutcome ExtractLane(const Run* runs, int run_count, const Ipm& ipm,
                            const IpmErrorModel& error_model, const ExtractionOptions& options,
                            LaneObservation* lane);

// The rectangle with sides along `axis` (and across it) spanning `outline`,
// counter-clockwise. `outline` must have at least one point, `axis` must not be zero.
std::array<Eigen::Vector2d, 4> BoundingRectangle(const std::vector<Eigen::Vector2d>& outline,
                                                 const Eigen::Vector2d& axis);

// Reorders ground corners canonically: first the corner nearest base_link's origin, then
// counter-clockwise seen from above (positive signed area in x-y).
void OrderCornersCanonically(std::array<Eigen::Vector3d, 4>* corners_base);

}  // namespace extraction
}  // namespace ipm_road_mapper
