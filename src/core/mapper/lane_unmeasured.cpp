#include "ipm_road_mapper/core/mapper/lane_unmeasured.h"

#include <algorithm>

namespace ipm_road_mapper {

bool ControlPointUnmeasured(const LaneElement& lane, std::size_t local) {
  const std::int64_t global = lane.first_cp_index + static_cast<std::int64_t>(local);
  for (const IndexRange& range : lane.unmeasured_cps) {
    if (global >= range.first && global <= range.second) return true;
  }
  return false;
}

std::vector<std::pair<std::size_t, std::size_t>> ExportedUnmeasured(const LaneElement& lane,
                                                                    std::size_t from,
                                                                    std::size_t count) {
  std::vector<std::pair<std::size_t, std::size_t>> exported;
  if (count == 0) return exported;
  const std::int64_t first = lane.first_cp_index + static_cast<std::int64_t>(from);
  const std::int64_t last = first + static_cast<std::int64_t>(count) - 1;
  for (const IndexRange& range : lane.unmeasured_cps) {
    const std::int64_t a = std::max(range.first, first), b = std::min(range.second, last);
    if (a <= b)
      exported.emplace_back(static_cast<std::size_t>(a - first),
                            static_cast<std::size_t>(b - first));
  }
  return exported;
}

}  // namespace ipm_road_mapper
