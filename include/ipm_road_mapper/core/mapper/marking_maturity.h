// When a marking element reaches the back end and when it may correct poses: the rules the
// window snapshot and the final global solve share.
#pragma once

#include <cstddef>

#include "ipm_road_mapper/core/map/road_map.h"

namespace ipm_road_mapper {

// A marking enters the back end once it has been seen from this close: seen only from
// 15-20 m, with the odometry's 0.1 m of noise on the baseline, its triangulated depth is off
// by meters (4.5 m observed), worse than the front end's IPM average, and the association
// then starts a duplicate. It corrects poses after one solve and this many observations.
constexpr double kMatureRangeM = 15.0;
constexpr std::size_t kMinMatureObservations = 5;

// Whether the marking has been seen from within kMatureRangeM of base_link.
bool SeenUpClose(const MarkingElement& m);

// Whether no view of the marking showed it whole (larger than the view, or cut in every one).
bool SeenOnlyInPartialViews(const MarkingElement& m);

}  // namespace ipm_road_mapper
