// What the mapper did or refused, by reason (printed in summaries, published as
// diagnostics, written into the map's metadata), and the front end's timings.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "ipm_road_mapper/core/frontend/mask_sanity.h"
#include "ipm_road_mapper/core/frontend/observations.h"
#include "ipm_road_mapper/core/mapper/timing_series.h"

namespace ipm_road_mapper {

// Counters of everything the mapper did or refused.
struct MapperCounters {
  std::uint64_t frames_received = 0;
  std::uint64_t frames_used = 0;
  std::map<std::string, std::uint64_t> frames_skipped;  // reason key -> count
  MaskSanityCounters sanity;  // what the mask's sanity stage changed (mask_sanity.h)
  ExtractionCounters extraction;
  std::uint64_t markings_created = 0;
  std::uint64_t lanes_created = 0;
  std::uint64_t spurious_dropped = 0;
  std::uint64_t markings_inconsistent = 0;  // markings unseen where they should be: dropped
  // Markings made by far views that no near view found where they came into near view
  // (MarkingElement::far_only): dropped (the near views made the marking elsewhere, or none).
  std::uint64_t far_markings_dropped = 0;
  // ... and those a near view found: restarted from the near views.
  std::uint64_t far_markings_restarted = 0;
  std::uint64_t lanes_merged = 0;
  std::uint64_t lanes_joined = 0;  // fragments of one line joined end to start (lane_join.h)
  // ... of them across a gap longer than join_max_gap_m that no frame saw (lane_gap_visibility.h)
  std::uint64_t lanes_joined_hidden_gap = 0;
  std::uint64_t markings_merged = 0;
  std::uint64_t lane_observations_unused = 0;  // unmatched and too short / unfit to start a lane
  // Unmatched but close to a lane of its class (within twice the gates): not a new line, so
  // not started (a second spline along one line would be a duplicate).
  std::uint64_t lane_observations_near_lane = 0;
  // Unmatched and along a mapped lane of another class (a class flickering between solid and
  // dashed): not started, the same line.
  std::uint64_t lane_observations_other_class = 0;
  std::uint64_t results_applied = 0;   // back-end results merged into the map
  std::uint64_t results_rejected = 0;  // unusable (solver failure, trust bound)
  // Applied results whose refined extrinsic the guard refused (it explained the held-out
  // frames worse than the previous one, which was kept; window_problem.h).
  std::uint64_t extrinsic_rejected = 0;
  // Directions of the extrinsic the final global solve's joint step held because its data
  // did not observe them (window_problem.h, WindowResult::joint_extrinsic_held).
  std::uint64_t joint_extrinsic_held = 0;
  std::uint64_t SkippedTotal() const;
};

// Wall time of the front end per used frame (mask -> observations -> map update; the back
// end's snapshot and merges excluded), for the summaries and the benchmark; the most recent
// frames only (timing_series.h).
struct FrontEndTiming {
  std::vector<float> extraction_ms;  // mask -> instances -> IPM measurements
  std::vector<float> total_ms;       // extraction + orientation, association, map update
};

}  // namespace ipm_road_mapper
