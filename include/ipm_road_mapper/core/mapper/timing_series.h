// Per-event durations (front-end frames, window solves) kept for summaries, map metadata and
// diagnostics. Only the most recent ones are kept, so a vehicle that maps for hours keeps
// flat memory, and the map export (published at a few Hz) a bounded cost.
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

namespace ipm_road_mapper {

// At 20 Hz, the last half hour or more of frames (the oldest half is dropped when full).
constexpr std::size_t kMaxTimingSamples = std::size_t{1} << 15;

template <typename T>
void AppendBounded(std::vector<T>* series, T value, std::size_t cap = kMaxTimingSamples) {
  if (cap > 1 && series->size() >= cap) {
    series->erase(series->begin(), series->begin() + static_cast<std::ptrdiff_t>(cap / 2));
  }
  series->push_back(value);
}

// The q-quantile (0..1; 1 = the maximum) of a series; 0 when empty.
template <typename T>
double Quantile(std::vector<T> series, double q) {
  if (series.empty()) return 0.0;
  const std::size_t k =
      std::min(series.size() - 1, static_cast<std::size_t>(q * static_cast<double>(series.size())));
  std::nth_element(series.begin(), series.begin() + static_cast<std::ptrdiff_t>(k), series.end());
  return static_cast<double>(series[k]);
}

}  // namespace ipm_road_mapper
