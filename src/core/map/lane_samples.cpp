#include "ipm_road_mapper/core/map/lane_samples.h"

#include <stdexcept>

#include "ipm_road_mapper/core/geometry/catmull_rom_spline.h"
#include "ipm_road_mapper/core/map/index_ranges.h"

namespace ipm_road_mapper {

std::vector<bool> UnmeasuredPointFlags(const MapLane& lane) {
  const std::size_t n = lane.control_points_map.size();
  std::vector<bool> flags(n, false);
  for (const auto& [first, last] : lane.unmeasured) {
    for (std::size_t i = first; i <= last && i < n; ++i) flags[i] = true;
  }
  return flags;
}

void SetUnmeasuredFrom(std::size_t first_index, const std::vector<bool>& flags, MapLane* lane) {
  auto& ranges = lane->unmeasured;
  while (!ranges.empty() && ranges.back().first >= first_index) ranges.pop_back();
  if (!ranges.empty() && ranges.back().second >= first_index) {
    ranges.back().second = first_index - 1;  // first_index > ranges.back().first >= 0
  }
  for (const auto& range : RangesOfFlags(flags, first_index)) {
    if (!ranges.empty() && ranges.back().second + 1 == range.first) {
      ranges.back().second = range.second;
    } else {
      ranges.push_back(range);
    }
  }
}

LaneSamples SampleLane(const std::vector<Eigen::Vector3d>& control_points,
                       const std::vector<bool>& point_unmeasured, double spacing_m) {
  if (point_unmeasured.size() != control_points.size()) {
    throw std::invalid_argument("SampleLane: one unmeasured flag per control point");
  }
  const CatmullRomSpline spline(control_points);
  LaneSamples samples;
  for (double s : spline.SampleParametersByArcLength(spacing_m)) {
    samples.points.push_back(spline.Evaluate(s));
    int segment = 0;
    double u = 0.0;
    spline.Locate(s, &segment, &u);
    samples.unmeasured.push_back(point_unmeasured[segment + 1] || point_unmeasured[segment + 2]);
  }
  return samples;
}

}  // namespace ipm_road_mapper
