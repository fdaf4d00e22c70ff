// Whether the class table is the masks' own, told by the sizes of the markings extracted.
// A mask id means what the segmentation network's table says; a table that gives the id to
// another class bounds its views by the wrong sizes. av2_pit_dev mapped with the package's
// table instead of its own `classes.yaml` is the example: its id 10 is a pedestrian crossing
// 17-26 m across, the package's id 10 an arrow of at most 10 x 4 m, and every view of the
// crossings that reaches the size check is dropped as oversized. Nothing is mapped wrong,
// but nothing is mapped, and only the count of oversized markings says why. A class most of
// whose views exceed its bounds is named, so the user can check the table.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "ipm_road_mapper/core/frontend/class_table.h"
#include "ipm_road_mapper/core/frontend/observations.h"

namespace ipm_road_mapper {

// A class is judged once this many of its views were sized, and named when more than this
// fraction of them were oversized. Real markings are oversized only where segmentation
// merges a marking with a neighbour or a blob (none of the benchmark's drives has one); a
// misread class is oversized in most views that reach the check.
constexpr std::uint64_t kMinSizedViewsToJudge = 20;
constexpr double kMaxOversizedFraction = 0.5;

// A marking class whose views mostly exceed its size bounds.
struct OversizedClass {
  int class_id = 0;
  std::string name;
  double max_length_m = 0.0;
  double max_width_m = 0.0;
  std::uint64_t oversized = 0;  // views larger than the bounds (dropped)
  std::uint64_t sized = 0;      // views whose size was judged
};

// The marking classes of `classes` with at least kMinSizedViewsToJudge sized views of which
// more than kMaxOversizedFraction were oversized, by class id.
std::vector<OversizedClass> MostlyOversizedClasses(const ExtractionCounters& counters,
                                                   const ClassTable& classes);

// One line for a user: the class, its bounds, the counts and what to check.
std::string Describe(const OversizedClass& c);

}  // namespace ipm_road_mapper
