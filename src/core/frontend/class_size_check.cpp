#include "ipm_road_mapper/core/frontend/class_size_check.h"

#include <cstdio>

namespace ipm_road_mapper {

static_assert(kClassIdSlots == kMaxClassId + 1, "one counter slot per class id");

std::vector<OversizedClass> MostlyOversizedClasses(const ExtractionCounters& counters,
                                                   const ClassTable& classes) {
  std::vector<OversizedClass> suspects;
  for (const auto& [id, info] : classes.classes()) {
    if (info.kind != ElementKind::kMarking || id < 0 || id >= kClassIdSlots) continue;
    const std::uint64_t sized = counters.markings_sized_by_class[id];
    const std::uint64_t oversized = counters.markings_oversized_by_class[id];
    if (sized < kMinSizedViewsToJudge) continue;
    if (static_cast<double>(oversized) <= kMaxOversizedFraction * static_cast<double>(sized)) {
      continue;
    }
    suspects.push_back({id, info.name, info.max_length_m, info.max_width_m, oversized, sized});
  }
  return suspects;
}

std::string Describe(const OversizedClass& c) {
  char text[320];
  std::snprintf(
      text, sizeof(text),
      "class %d '%s' (at most %.1f x %.1f m): %llu of %llu views larger, dropped; "
      "is the class table the masks' own? (map_from_bag --classes; live: ros/classes_file)",
      c.class_id, c.name.c_str(), c.max_length_m, c.max_width_m,
      static_cast<unsigned long long>(c.oversized), static_cast<unsigned long long>(c.sized));
  return text;
}

}  // namespace ipm_road_mapper
