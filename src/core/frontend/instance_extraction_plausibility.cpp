// Plausibility checks of the instance extraction: what no real lane line or marking
// produces (a lane run wider than a line, a marking larger than its class, a frame whose
// foreground covers the road). See instance_extraction_runs.h.
#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "instance_extraction_runs.h"

namespace ipm_road_mapper {
namespace extraction {
namespace {

// minAreaRect works in float: ground points go in as millimeters relative to the first
// outline point, so float rounding stays far below the pixel footprint.
constexpr double kMetersToMm = 1000.0;

}  // namespace

std::optional<double> RunGroundWidth(const Run& run, const Ipm& ipm) {
  Eigen::Vector3d left_base, right_base;
  if (ipm.PixelToGround(Eigen::Vector2d(run.first_col - 0.5, run.row), &left_base) !=
          IpmStatus::kOk ||
      ipm.PixelToGround(Eigen::Vector2d(run.last_col + 0.5, run.row), &right_base) !=
          IpmStatus::kOk) {
    return std::nullopt;
  }
  return (right_base - left_base).head<2>().norm();
}

bool IsOversized(const std::vector<Eigen::Vector2d>& outline_base, const ClassInfo& class_info) {
  if (outline_base.empty()) return false;
  std::vector<cv::Point2f> points_mm;
  points_mm.reserve(outline_base.size());
  for (const Eigen::Vector2d& p : outline_base) {
    const Eigen::Vector2d d_mm = (p - outline_base.front()) * kMetersToMm;
    points_mm.emplace_back(static_cast<float>(d_mm.x()), static_cast<float>(d_mm.y()));
  }
  const cv::RotatedRect rectangle = cv::minAreaRect(points_mm);
  const double long_side_m = std::max(rectangle.size.width, rectangle.size.height) / kMetersToMm;
  const double short_side_m = std::min(rectangle.size.width, rectangle.size.height) / kMetersToMm;
  return long_side_m > class_info.max_length_m || short_side_m > class_info.max_width_m;
}

int PixelsBelowHorizon(const Ipm& ipm, int row, int first_col, int last_col) {
  // A pixel's ray in base_link is R_base_cam * ((u - cx) / fx, (v - cy) / fy, 1); its z
  // component, alpha * u + beta along a row (r the last row of R_base_cam), is negative
  // below the horizon: an interval of columns.
  const CameraIntrinsics& in = ipm.camera().intrinsics();
  const Eigen::RowVector3d r = ipm.T_base_cam().linear().row(2);
  const double alpha = r(0) / in.fx;
  const double beta = -alpha * in.cx + r(1) * (row - in.cy) / in.fy + r(2);
  double first = first_col, last = last_col;
  if (std::abs(alpha) < 1e-15) {
    if (beta >= 0.0) return 0;
  } else if (alpha > 0.0) {
    last = std::min(last, std::ceil(-beta / alpha) - 1.0);  // u < -beta / alpha
  } else {
    first = std::max(first, std::floor(-beta / alpha) + 1.0);  // u > -beta / alpha
  }
  return last >= first ? static_cast<int>(last - first) + 1 : 0;
}

bool CoversMoreThan(const Ipm& ipm, const MaskRuns& scan, const std::vector<int>& slots,
                    double max_coverage) {
  const CameraIntrinsics& in = ipm.camera().intrinsics();
  std::uint64_t below = 0;
  for (int row = 0; row < in.height; ++row) below += PixelsBelowHorizon(ipm, row, 0, in.width - 1);
  if (below == 0) return false;
  const double limit = max_coverage * static_cast<double>(below);
  std::vector<bool> counted(scan.instances.size(), false);
  std::uint64_t pixels = 0;
  for (int slot : slots) {
    counted[slot] = true;
    pixels += scan.instances[slot].pixel_count;
  }
  // Most frames end here: even all their pixels (some above the horizon) are few enough.
  if (static_cast<double>(pixels) <= limit) return false;
  std::uint64_t covered = 0;
  for (const Run& run : scan.runs) {
    if (counted[run.slot]) covered += PixelsBelowHorizon(ipm, run.row, run.first_col, run.last_col);
  }
  return static_cast<double>(covered) > limit;
}

}  // namespace extraction
}  // namespace ipm_road_mapper
