// Mapper::ExportSnapshot: the live snapshot's export in shared storage (snapshot_cache.h).
#include <algorithm>

#include "ipm_road_mapper/core/mapper/lane_unmeasured.h"
#include "ipm_road_mapper/core/mapper/mapper.h"

namespace ipm_road_mapper {

SharedVectorMap Mapper::ExportSnapshot(std::size_t max_trajectory_poses,
                                       SnapshotCache* cache) const {
  const ChangeLog& log = store_.changes();
  // A cache of this map before a ~reset, or of a revision it never had, starts over.
  if (cache->revision < log.cleared_at() || cache->revision > log.revision()) cache->Clear();
  const std::uint64_t since = cache->revision;
  SharedVectorMap out;
  ExportHeader(max_trajectory_poses, cache, &out.header);

  // The live markings change at every frame and are few: exported afresh.
  auto live = std::make_shared<MarkingChunk>();
  for (const MarkingElement& m : store_.markings()) {
    MapMarking marking;
    if (ExportMarking(m, &marking)) live->push_back(std::move(marking));
  }
  out.marking_chunks.push_back(std::move(live));

  // The retired chunks whose slots changed: new chunks, the last one when the count changed
  // (a retirement appended, a revival popped), the slots of markings touched since, and the
  // slots a revival moved another marking into.
  const std::vector<MarkingElement>& retired = store_.retired_markings();
  const std::size_t slots = cache->retired_chunk_slots;
  const std::size_t chunk_count = (retired.size() + slots - 1) / slots;
  std::vector<bool> dirty(chunk_count, false);
  for (std::size_t k = std::min(cache->retired_chunks.size(), chunk_count); k < chunk_count; ++k) {
    dirty[k] = true;
  }
  if (retired.size() != cache->retired_count && chunk_count > 0) dirty[chunk_count - 1] = true;
  for (const auto& [revision, id] : log.RetiredSince(since)) {
    const std::int64_t index = store_.RetiredIndexOf(id);
    if (index >= 0) dirty[static_cast<std::size_t>(index) / slots] = true;
  }
  for (std::size_t slot : log.RetiredMovedSince(since)) {
    if (slot < retired.size()) dirty[slot / slots] = true;
  }
  cache->retired_chunks.resize(chunk_count);
  cache->chunks_built = 0;
  for (std::size_t k = 0; k < chunk_count; ++k) {
    if (!dirty[k]) continue;
    auto chunk = std::make_shared<MarkingChunk>();
    for (std::size_t i = k * slots; i < std::min(retired.size(), (k + 1) * slots); ++i) {
      MapMarking marking;
      if (ExportMarking(retired[i], &marking)) chunk->push_back(std::move(marking));
    }
    cache->retired_chunks[k] = std::move(chunk);
    ++cache->chunks_built;
  }
  cache->retired_count = retired.size();
  out.marking_chunks.insert(out.marking_chunks.end(), cache->retired_chunks.begin(),
                            cache->retired_chunks.end());

  // Lanes: re-used while their revision stands; a changed lane keeps the chunks before the
  // first point that changed since the last export (ChangeLog lane ranges) and rebuilds the
  // rest. Lanes re-fit at export follow the extrinsic and every pose, so then all are
  // exported afresh and whole.
  const bool refit = !windows_.LanesRefined();
  const std::size_t chunk_points = cache->lane_chunk_points;
  decltype(cache->lanes) lanes;
  lanes.reserve(store_.lanes().size());
  cache->lanes_built = 0;
  cache->lane_points_built = 0;
  for (const LaneElement& element : store_.lanes()) {
    std::shared_ptr<const SharedLane> lane;
    const auto cached = cache->lanes.find(element.id);
    const bool have = !refit && cached != cache->lanes.end();
    if (have && cached->second.first == element.revision) {
      lane = cached->second.second;
    } else {
      // Whole chunks before the first changed point, and no more than the lane still has.
      std::size_t keep = 0;
      if (have) {
        const SharedLane& before = *cached->second.second;
        const std::size_t from = std::min({log.LaneChangedFrom(element.id, since),
                                           element.control_points_map.size(), before.PointCount()});
        keep = from / chunk_points;
      }
      MapLane exported;
      if (!ExportLane(element, &exported, keep * chunk_points)) continue;
      // The fields are the whole lane's: its unmeasured points over the kept chunks too.
      exported.unmeasured =
          ExportedUnmeasured(element, 0, keep * chunk_points + exported.control_points_map.size());
      cache->lane_points_built += exported.control_points_map.size();
      std::shared_ptr<SharedLane> built = ShareLane(std::move(exported), chunk_points);
      if (keep > 0) {
        const auto& old_chunks = cached->second.second->point_chunks;
        built->point_chunks.insert(built->point_chunks.begin(), old_chunks.begin(),
                                   old_chunks.begin() + keep);
      }
      lane = std::move(built);
      ++cache->lanes_built;
    }
    out.lanes.push_back(lane);
    lanes.emplace(element.id, std::make_pair(element.revision, std::move(lane)));
  }
  cache->lanes = std::move(lanes);
  cache->revision = log.revision();
  return out;
}

}  // namespace ipm_road_mapper
