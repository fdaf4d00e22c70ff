// An incremental export (Mapper::ExportChanges): the elements whose exported form changed
// since a revision of the map, and the ids that left the exported map since then, so that a
// publisher's cost follows what changed and not the map's length (retired markings that no
// solve moves any more cost nothing). Revisions come from MapStore::Touch (change_log.h).
#pragma once

#include <cstdint>
#include <vector>

#include "ipm_road_mapper/core/map/vector_map.h"

namespace ipm_road_mapper {

struct MapChanges {
  std::uint64_t since = 0;     // the revision asked for
  std::uint64_t revision = 0;  // the map's revision now: the `since` of the next request
  // True when `map` holds every exported element (since 0, or the map was reset after
  // `since`): what is not in it left the map, and the removed ids are empty.
  bool complete = false;
  // The extrinsic fields as ExportMap's, and the exported markings and lanes that changed
  // after `since`, as ExportMap shows them and in its order (live markings, then retired
  // ones, then lanes). No trajectory, no lane topology, no metadata.
  VectorMap map;
  // Ids exported before that the map no longer exports (merged away, dropped, joined into
  // another lane, or changed into a form export skips), sorted. May name ids never exported.
  std::vector<std::uint64_t> removed_marking_ids;
  std::vector<std::uint64_t> removed_lane_ids;
};

}  // namespace ipm_road_mapper
