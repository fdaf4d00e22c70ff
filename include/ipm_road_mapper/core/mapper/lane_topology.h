// Lane topology for the exported map: which lanes continue which. A lane whose start lies on
// another lane's curve (within radius_m, in its direction) continues from it: at the other's
// end (a line that goes on in another class: solid to dashed) or leaving it (a fork's
// branch, which starts at the fork while the other goes on). A lane whose end lies on
// another's likewise leads into it (a merge). Lanes that run along each other (a double
// line's halves) are not linked.
#pragma once

#include <vector>

#include "ipm_road_mapper/core/map/vector_map.h"

namespace ipm_road_mapper {

// Fills every lane's `predecessors` and `successors` (replacing what they held).
void LinkLaneTopology(std::vector<MapLane>* lanes, double radius_m = 0.5);

}  // namespace ipm_road_mapper
