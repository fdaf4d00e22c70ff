#include "ipm_road_mapper/core/mapper/lane_gap_visibility.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace ipm_road_mapper {
namespace {

// Frames walked at most, each way, to cover the look-around travel (a standstill adds
// frames without travel).
constexpr std::size_t kMaxWalkFrames = 600;

// The frame index reached by walking from `start` in `step` (+1 / -1) until the vehicle is
// `distance_m` (in the plane) from where it was at `start`.
std::size_t Walk(const std::vector<FrameRecord>& frames, std::size_t start, int step,
                 double distance_m) {
  const Eigen::Vector2d origin = frames[start].T_map_base.translation().head<2>();
  std::size_t i = start;
  for (std::size_t walked = 0; walked < kMaxWalkFrames; ++walked) {
    if (step < 0 ? i == 0 : i + 1 >= frames.size()) break;
    i = step < 0 ? i - 1 : i + 1;
    if ((frames[i].T_map_base.translation().head<2>() - origin).norm() > distance_m) break;
  }
  return i;
}

// A point of the gap and its horizontal unit normal (zero where the polyline has no extent).
struct GapSample {
  Eigen::Vector3d p_map;
  Eigen::Vector3d normal_map;
};

// `polyline` sampled every `spacing_m` along each segment, its vertices included.
std::vector<GapSample> Sampled(const std::vector<Eigen::Vector3d>& polyline, double spacing_m) {
  std::vector<GapSample> samples;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < polyline.size(); ++i) {
    if (i + 1 == polyline.size()) {
      samples.push_back({polyline[i], normal});
      break;
    }
    const Eigen::Vector3d step = polyline[i + 1] - polyline[i];
    const double length = step.head<2>().norm();
    if (length > 0.0) normal = Eigen::Vector3d(-step.y(), step.x(), 0.0) / length;
    const int n = std::max(1, static_cast<int>(std::ceil(step.norm() / spacing_m)));
    for (int k = 0; k < n; ++k) samples.push_back({polyline[i] + step * (double(k) / n), normal});
  }
  return samples;
}

bool SeenInFrame(const std::vector<GapSample>& gap_samples, const FrameRecord& frame,
                 const GapCamera& camera, const GapViewOptions& options) {
  const Eigen::Isometry3d T_base_map = frame.T_map_base.inverse();
  const Eigen::Isometry3d T_cam_map = camera.T_base_cam.inverse() * T_base_map;
  const auto in_image = [&](const Eigen::Vector3d& p_map, Eigen::Vector2d* uv) {
    return camera.camera.Project(Eigen::Vector3d(T_cam_map * p_map), uv) &&
           camera.camera.InImage(*uv, options.border_margin_px);
  };
  const Eigen::Vector3d* first_seen = nullptr;
  for (const GapSample& sample : gap_samples) {
    const Eigen::Vector3d& p_map = sample.p_map;
    const Eigen::Vector3d p_base = T_base_map * p_map;
    if (p_base.head<2>().norm() > options.max_range_m) continue;
    Eigen::Vector2d uv, aside;
    const Eigen::Vector3d across = options.lateral_uncertainty_m * sample.normal_map;
    if (!in_image(p_map, &uv) || !in_image(p_map + across, &aside) ||
        !in_image(p_map - across, &aside)) {
      continue;
    }
    const std::optional<IpmUncertainty> uncertainty =
        ComputeIpmUncertainty(camera.camera, camera.T_base_cam, uv, camera.error_model);
    if (!uncertainty || uncertainty->score > options.max_point_score_m2) continue;
    if (!first_seen) first_seen = &p_map;
    if ((p_map - *first_seen).head<2>().norm() >= options.min_seen_length_m) return true;
  }
  return false;
}

}  // namespace

FrameSpan GapFrameSpan(const std::vector<FrameRecord>& frames, std::size_t first_last_frame,
                       std::size_t second_first_frame, double lookaround_m) {
  if (frames.empty()) return {};
  const std::size_t last = frames.size() - 1;
  const std::size_t a = std::min(std::min(first_last_frame, second_first_frame), last);
  const std::size_t b = std::min(std::max(first_last_frame, second_first_frame), last);
  return {Walk(frames, a, -1, lookaround_m), Walk(frames, b, +1, lookaround_m) + 1};
}

std::size_t FramesThatSawGap(const std::vector<Eigen::Vector3d>& gap_points_map,
                             const std::vector<FrameRecord>& frames, const FrameSpan& span,
                             const GapCamera& camera, const GapViewOptions& options) {
  const std::size_t to = std::min(span.to, frames.size());
  if (span.from >= to || gap_points_map.empty()) return 0;
  if (camera.camera.intrinsics().width <= 0) return std::numeric_limits<std::size_t>::max();
  const std::size_t count = to - span.from;
  const std::size_t stride =
      std::max<std::size_t>(1, (count + std::max<std::size_t>(options.max_frames, 1) - 1) /
                                   std::max<std::size_t>(options.max_frames, 1));
  const std::vector<GapSample> samples = Sampled(gap_points_map, kGapSampleSpacingM);
  std::size_t seen = 0;
  for (std::size_t i = span.from; i < to; i += stride) {
    if (SeenInFrame(samples, frames[i], camera, options)) seen += stride;
  }
  return seen;
}

}  // namespace ipm_road_mapper
