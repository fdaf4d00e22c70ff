// Which lane data a window sees: the frames whose lane observations still enter windows, and
// the part of a (possibly kilometers long) lane near a window's measurements.
#pragma once

#include <cstddef>
#include <vector>

#include "ipm_road_mapper/core/backend/backend_options.h"
#include "ipm_road_mapper/core/backend/window_problem.h"
#include "ipm_road_mapper/core/map/road_map.h"

namespace ipm_road_mapper {

// The first frame whose lane observations still enter a window (the window's frames and one
// more window of context before them; BuildSnapshot), for `frame_count` frames: lane data
// of older frames is settled, no window moves anything with it any more.
std::size_t LaneContextStart(const BackendOptions& options, std::size_t frame_count);

// The part of a lane a window needs: the control points near its measurements' points (at
// the frames' current poses), with a margin of two chords and the pixel gate, plus two more
// on each side, so that every segment a pixel can fall on, and every smoothness triple
// touching a point that can move, lies inside. A lane can be kilometers long; a window
// looks at tens of meters of it. Writes the part and its global index of the first point.
void SliceForWindow(const LaneElement& lane, const std::vector<const LaneMeasurement*>& window,
                    const std::vector<FrameRecord>& frames, double margin_m, WindowLane* out);

}  // namespace ipm_road_mapper
