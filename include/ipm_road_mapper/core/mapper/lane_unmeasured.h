// Which of a lane's control points no pixel measured: those a join laid across a gap in the
// line's observations, interpolated between the two fragments' ends (JoinLanes) or along the
// driven path where no frame saw the line (JoinLanesThrough, lane_path_bridge.h). The map
// draws them as a line like any other, so a user who takes the line for measured paint
// (a Lanelet2 boundary) must be told where it is only laid. A point stays flagged when a
// later view measures it (a second pass over the road): the flag never claims too little.
//
// A lane keeps them as ranges of global control-point indices (LaneElement::unmeasured_cps,
// first_cp_index's), which stay valid while the lane grows at either end and while back-end
// results are applied point by point; a join carries them into the joined lane (the flags
// of each point it keeps); the export turns them into ranges of the exported points
// (MapLane::unmeasured, map.json `unmeasured`).
#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "ipm_road_mapper/core/map/road_map.h"

namespace ipm_road_mapper {

using IndexRange = std::pair<std::int64_t, std::int64_t>;  // inclusive

// Whether `lane`'s control point at `local` (an index into control_points_map) is unmeasured.
bool ControlPointUnmeasured(const LaneElement& lane, std::size_t local);

// The lane's unmeasured control points among `count` exported ones, control_points_map's
// from local index `from` on: inclusive ranges of exported indices (0 = local `from`).
std::vector<std::pair<std::size_t, std::size_t>> ExportedUnmeasured(const LaneElement& lane,
                                                                    std::size_t from,
                                                                    std::size_t count);

}  // namespace ipm_road_mapper
