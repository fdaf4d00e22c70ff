// Runs of set flags as inclusive index ranges: how lanes keep and export the control points
// no pixel measured (lane_unmeasured.h, MapLane::unmeasured).
#pragma once

#include <cstddef>
#include <utility>
#include <vector>

namespace ipm_road_mapper {

// The maximal runs of set `flags` as inclusive [first, last] ranges, ascending; the first
// flag is at index `first_index`.
template <typename Index>
std::vector<std::pair<Index, Index>> RangesOfFlags(const std::vector<bool>& flags,
                                                   Index first_index) {
  std::vector<std::pair<Index, Index>> ranges;
  for (std::size_t i = 0; i < flags.size(); ++i) {
    if (!flags[i]) continue;
    const Index index = first_index + static_cast<Index>(i);
    if (!ranges.empty() && ranges.back().second + 1 == index) {
      ranges.back().second = index;
    } else {
      ranges.emplace_back(index, index);
    }
  }
  return ranges;
}

}  // namespace ipm_road_mapper
