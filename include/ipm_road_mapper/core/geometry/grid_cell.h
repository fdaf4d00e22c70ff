// The cell of a uniform grid that holds a coordinate: what the spatial indices (FrameIndex,
// the lanelet pairing's segment grid) share.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace ipm_road_mapper {

// The index of the grid cell `cell_m` wide (> 0) that holds coordinate v (m). Coordinates
// beyond +-1e12 m share the outermost cells and a non-finite one is cell 0, so the cast to an
// integer is always defined (a hostile map's 1e300 m point lands somewhere, harmlessly).
inline std::int64_t GridCell(double v, double cell_m) {
  constexpr double kLimitM = 1e12;
  const double clamped = std::isfinite(v) ? std::clamp(v, -kLimitM, kLimitM) : 0.0;
  return static_cast<std::int64_t>(std::floor(clamped / cell_m));
}

}  // namespace ipm_road_mapper
