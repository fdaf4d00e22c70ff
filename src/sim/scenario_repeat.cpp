#include <string>
#include <vector>

#include "ipm_road_mapper/sim/scenario.h"

namespace ipm_road_mapper {
namespace sim {

void RepeatRoute(int count, ScenarioOptions* scenario) {
  if (count < 1) throw OptionsError("repeat_count: must be >= 1");
  RoadOptions& road = scenario->road;
  double length_m = 0.0;
  for (const RoadSegmentOptions& segment : road.segments) length_m += segment.length_m;
  std::vector<GradeKnot>& grade = road.surface.grade;
  if (count > 1 && !grade.empty() && grade.back().s_m >= grade.front().s_m + length_m) {
    throw OptionsError("repeat_count: road.surface.grade knots span " +
                       std::to_string(grade.back().s_m - grade.front().s_m) +
                       " m, must be less than the road length (" + std::to_string(length_m) +
                       " m) to repeat");
  }
  const std::vector<RoadSegmentOptions> segments = road.segments;
  const std::vector<GradeKnot> knots = grade;
  const std::vector<SurfaceBump> bumps = road.surface.bumps;
  const std::vector<MarkingPlacement> markings = scenario->markings;
  for (int copy = 1; copy < count; ++copy) {
    const double shift_m = copy * length_m;
    road.segments.insert(road.segments.end(), segments.begin(), segments.end());
    for (GradeKnot knot : knots) {
      knot.s_m += shift_m;
      grade.push_back(knot);
    }
    for (SurfaceBump bump : bumps) {
      bump.s_m += shift_m;
      road.surface.bumps.push_back(bump);
    }
    for (MarkingPlacement marking : markings) {
      marking.s_m += shift_m;
      scenario->markings.push_back(marking);
    }
  }
}

}  // namespace sim
}  // namespace ipm_road_mapper
