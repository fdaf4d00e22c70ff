// Whether two map elements were observed in one frame: their histories (measurements in
// ascending frame_index) share a frame index. Two instances of one frame are two elements,
// so such elements are never merged or joined (markings: marking_tracker; lanes: lane_join).
#pragma once

namespace ipm_road_mapper {

// True when some frame index appears in both `a.history` and `b.history` (each sorted by
// frame_index): a merge walk, linear in the two histories.
template <typename ElementA, typename ElementB>
bool SeenInOneFrame(const ElementA& a, const ElementB& b) {
  auto i = a.history.begin();
  auto j = b.history.begin();
  while (i != a.history.end() && j != b.history.end()) {
    if (i->frame_index == j->frame_index) return true;
    if (i->frame_index < j->frame_index) {
      ++i;
    } else {
      ++j;
    }
  }
  return false;
}

}  // namespace ipm_road_mapper
