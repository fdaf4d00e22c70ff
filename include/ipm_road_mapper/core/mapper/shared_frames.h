// Whether two map elements were observed in one frame: their histories (measurements in
// ascending frame_index) share a frame index. Two instances of one frame are two elements,
// so such markings are never merged (marking_tracker); two lane instances of one frame are
// two lines when they lie side by side (lane_join's CoObserved, through AnySharedFrame).
#pragma once

namespace ipm_road_mapper {

// True when some frame index appears in both `a.history` and `b.history` (each sorted by
// frame_index) and `counts(ma, mb)` holds for the two measurements of that frame: a merge
// walk, linear in the two histories.
template <typename ElementA, typename ElementB, typename Counts>
bool AnySharedFrame(const ElementA& a, const ElementB& b, Counts counts) {
  auto i = a.history.begin();
  auto j = b.history.begin();
  while (i != a.history.end() && j != b.history.end()) {
    if (i->frame_index == j->frame_index) {
      if (counts(*i, *j)) return true;
      ++i;
      ++j;
    } else if (i->frame_index < j->frame_index) {
      ++i;
    } else {
      ++j;
    }
  }
  return false;
}

// True when some frame index appears in both `a.history` and `b.history`.
template <typename ElementA, typename ElementB>
bool SeenInOneFrame(const ElementA& a, const ElementB& b) {
  return AnySharedFrame(a, b, [](const auto&, const auto&) { return true; });
}

}  // namespace ipm_road_mapper
