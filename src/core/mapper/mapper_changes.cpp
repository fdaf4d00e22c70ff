// Mapper::ExportChanges: the incremental export (map_changes.h).
#include <algorithm>

#include "ipm_road_mapper/core/mapper/mapper.h"

namespace ipm_road_mapper {
namespace {

void SortUnique(std::vector<std::uint64_t>* ids) {
  std::sort(ids->begin(), ids->end());
  ids->erase(std::unique(ids->begin(), ids->end()), ids->end());
}

}  // namespace

MapChanges Mapper::ExportChanges(std::uint64_t since, const ChangesOptions& options) const {
  const ChangeLog& log = store_.changes();
  MapChanges out;
  out.revision = log.revision();
  // A revision this map never had (a client of another Mapper) asks for everything too.
  out.complete = since == 0 || since < log.cleared_at() || since > log.revision();
  if (out.complete) since = 0;
  out.since = since;
  ExportExtrinsic(&out.map);
  // A changed element export skips now (never exported, or no longer): removed if it was.
  auto add_marking = [&](const MarkingElement& m) {
    MapMarking marking;
    if (ExportMarking(m, &marking)) {
      out.map.markings.push_back(std::move(marking));
    } else if (!out.complete) {
      out.removed_marking_ids.push_back(m.id);
    }
  };
  for (const MarkingElement& m : store_.markings()) {
    if (m.revision > since) add_marking(m);
  }
  // The retired markings that changed (or retired) after `since`, in their export order;
  // an entry is current while the marking is retired and carries the entry's revision.
  std::vector<std::size_t> retired;
  for (const auto& [revision, id] : log.RetiredSince(since)) {
    const std::int64_t index = store_.RetiredIndexOf(id);
    if (index < 0) continue;
    if (store_.retired_markings()[static_cast<std::size_t>(index)].revision != revision) continue;
    retired.push_back(static_cast<std::size_t>(index));
  }
  std::sort(retired.begin(), retired.end());
  for (std::size_t index : retired) add_marking(store_.retired_markings()[index]);
  // Lanes re-fit at export follow the extrinsic and every pose: all of them change.
  const bool refit = !windows_.LanesRefined();
  for (const LaneElement& element : store_.lanes()) {
    if (!refit && element.revision <= since) continue;
    // The points before the first changed one are as the client has them; a lane exported
    // first after `since` is new to it.
    const std::size_t first_changed =
        refit || element.exported_at > since ? 0 : log.LaneChangedFrom(element.id, since);
    const std::size_t offset = first_changed > options.lane_context_points
                                   ? first_changed - options.lane_context_points
                                   : 0;
    MapLane lane;
    if (ExportLane(element, &lane, offset)) {
      out.map.lanes.push_back(std::move(lane));
      out.lane_first_changed.push_back(first_changed);
      out.lane_offsets.push_back(offset);
    } else if (!out.complete) {
      out.removed_lane_ids.push_back(element.id);
    }
  }
  if (!out.complete) {
    for (std::uint64_t id : log.RemovedSince(ElementKind::kMarking, since)) {
      out.removed_marking_ids.push_back(id);
    }
    for (std::uint64_t id : log.RemovedSince(ElementKind::kLane, since)) {
      out.removed_lane_ids.push_back(id);
    }
  }
  SortUnique(&out.removed_marking_ids);
  SortUnique(&out.removed_lane_ids);
  return out;
}

}  // namespace ipm_road_mapper
