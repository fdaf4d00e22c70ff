// Unit constants the shared test helpers use.
#pragma once

#include <cmath>

namespace ipm_road_mapper {

constexpr double kDeg = M_PI / 180.0;  // one degree in radians

}  // namespace ipm_road_mapper
