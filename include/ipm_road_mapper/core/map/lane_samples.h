// A lane line's curve sampled by arc length, with per sample whether it lies on a stretch no
// pixel measured (MapLane::unmeasured): what the exports draw, the markers colour and the
// evaluation scores apart. A sample is unmeasured when its spline segment has an unmeasured
// control point at either end (segment i runs from control point i + 1 to i + 2), so an
// unmeasured stretch runs from the last measured control point before it to the next.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "ipm_road_mapper/core/map/vector_map.h"

namespace ipm_road_mapper {

struct LaneSamples {
  std::vector<Eigen::Vector3d> points;  // CatmullRomSpline::SampleByArcLength's
  std::vector<bool> unmeasured;         // per point
};

// Per control point of `lane`: whether it is in one of its unmeasured ranges.
std::vector<bool> UnmeasuredPointFlags(const MapLane& lane);

// `lane`'s unmeasured ranges with those of its points from `first_index` on replaced by
// `flags` (one per point from there; a patch of the lane's tail).
void SetUnmeasuredFrom(std::size_t first_index, const std::vector<bool>& flags, MapLane* lane);

// The curve of `control_points` (at least 4, phantom ends included) sampled every spacing_m,
// with `point_unmeasured` per control point. Throws std::invalid_argument as CatmullRomSpline
// and SampleByArcLength do.
LaneSamples SampleLane(const std::vector<Eigen::Vector3d>& control_points,
                       const std::vector<bool>& point_unmeasured, double spacing_m);

}  // namespace ipm_road_mapper
