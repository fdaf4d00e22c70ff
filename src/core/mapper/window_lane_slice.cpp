#include "ipm_road_mapper/core/mapper/window_lane_slice.h"

#include <algorithm>

#include "ipm_road_mapper/core/geometry/catmull_rom_spline.h"

namespace ipm_road_mapper {

std::size_t LaneContextStart(const BackendOptions& options, std::size_t frame_count) {
  const std::size_t window = static_cast<std::size_t>(options.window_frames);
  const std::size_t first = frame_count > window ? frame_count - window : 0;
  return first > window ? first - window : 0;
}

// The part of a lane a window needs: the control points near its measurements' points (at
// the frames' current poses), with a margin of two chords and the pixel gate, plus two more
// on each side, so that every segment a pixel can fall on, and every smoothness triple
// touching a point that can move, lies inside. A lane can be kilometers long; a window
// looks at tens of meters of it. Writes the part and its global index of the first point.
void SliceForWindow(const LaneElement& lane, const std::vector<const LaneMeasurement*>& window,
                    const std::vector<FrameRecord>& frames, double margin_m, WindowLane* out) {
  std::vector<Eigen::Vector3d> points_map;
  for (const LaneMeasurement* m : window) {
    const Eigen::Isometry3d& T_map_base = frames[m->frame_index].T_map_base;
    for (std::size_t i = 0; i < m->points.size(); ++i) {
      if (m->selected[i]) points_map.push_back(T_map_base * m->points[i].p_base);
    }
  }
  const std::vector<Eigen::Vector3d>& cps = lane.control_points_map;
  std::size_t first = 0, last = cps.empty() ? 0 : cps.size() - 1;
  if (ControlPointRangeNear(cps, points_map, margin_m, &first, &last)) {
    first = first >= 2 ? first - 2 : 0;
    last = std::min(cps.size() - 1, last + 2);
  } else {
    first = 0;
    last = cps.empty() ? 0 : cps.size() - 1;
  }
  out->first_cp_index = lane.first_cp_index + static_cast<std::int64_t>(first);
  out->control_points_map.assign(cps.begin() + first,
                                 cps.empty() ? cps.end() : cps.begin() + last + 1);
}

}  // namespace ipm_road_mapper
