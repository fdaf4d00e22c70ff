// An incremental export (Mapper::ExportChanges): the elements whose exported form changed
// since a revision of the map, and the ids that left the exported map since then, so that a
// publisher's cost follows what changed and not the map's length (retired markings that no
// solve moves any more cost nothing; a lane kilometers long that changed at its end costs
// its end). Revisions come from MapStore::Touch (change_log.h).
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "ipm_road_mapper/core/map/vector_map.h"

namespace ipm_road_mapper {

// What ExportChanges puts in a changed lane.
struct ChangesOptions {
  // The control points a changed lane carries before its first changed one: the default
  // (the largest size_t) exports every changed lane whole; a publisher that remembers what it
  // sent asks for the few its chunks need (MapPublisher::ChangesNeeded), and a lane then
  // costs its changed part, not its length.
  std::size_t lane_context_points = std::numeric_limits<std::size_t>::max();
};

struct MapChanges {
  std::uint64_t since = 0;     // the revision asked for
  std::uint64_t revision = 0;  // the map's revision now: the `since` of the next request
  // True when `map` holds every exported element (since 0, or the map was reset after
  // `since`): what is not in it left the map, and the removed ids are empty.
  bool complete = false;
  // The extrinsic fields as ExportMap's, and the exported markings and lanes that changed
  // after `since`, as ExportMap shows them and in its order (live markings, then retired
  // ones, then lanes). No trajectory, no lane topology, no metadata. A lane holds its
  // control points from lane_offsets[i] on (0, the whole lane, by default).
  VectorMap map;
  // Per lane of map.lanes: the index (in the whole lane) of its first control point that
  // may differ from the export at `since`; the lane's class and its points before it are
  // as that export showed them. 0: the whole lane (new to that export, grown at its start,
  // re-fit, or changed by a writer that reported no range); the lane's point count when
  // only its other fields changed.
  std::vector<std::size_t> lane_first_changed;
  // Per lane of map.lanes: the index in the whole lane of its control_points_map[0], at
  // most lane_first_changed[i] (ChangesOptions::lane_context_points before it); the whole
  // lane has lane_offsets[i] + control_points_map.size() points.
  std::vector<std::size_t> lane_offsets;
  // Ids exported before that the map no longer exports (merged away, dropped, joined into
  // another lane, or changed into a form export skips), sorted. May name ids never exported.
  std::vector<std::uint64_t> removed_marking_ids;
  std::vector<std::uint64_t> removed_lane_ids;
};

}  // namespace ipm_road_mapper
