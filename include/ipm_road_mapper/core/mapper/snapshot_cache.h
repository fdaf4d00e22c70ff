// What Mapper::ExportSnapshot keeps from one export to the next, so that the next one
// rebuilds only the parts that changed and shares the rest: the retired markings' chunks
// (copy-on-write: a chunk is rebuilt when one of its slots changed, found through the
// ChangeLog, never by scanning), each lane's export with the revision it was made at, and
// the metadata's timing quantiles (kept up to date sample by sample: series_quantile.h).
// One cache per Mapper and per caller; not thread-safe (the exporting thread owns it). The
// snapshots it hands out are immutable and outlive it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <unordered_map>
#include <utility>

#include "ipm_road_mapper/core/map/shared_vector_map.h"
#include "ipm_road_mapper/core/mapper/series_quantile.h"

namespace ipm_road_mapper {

struct SnapshotCache {
  explicit SnapshotCache(std::size_t retired_chunk_slots = 64)
      : retired_chunk_slots(retired_chunk_slots > 0 ? retired_chunk_slots : 1) {}

  // Retired markings per chunk (> 0): chunk k exports retired slots [k * n, (k + 1) * n).
  std::size_t retired_chunk_slots;

  // The map's revision at the last export; 0: nothing cached (the next export builds all).
  std::uint64_t revision = 0;
  // The retired markings' count at the last export.
  std::size_t retired_count = 0;
  // The exported retired markings, one chunk per retired_chunk_slots slots.
  MarkingChunks retired_chunks;
  // Lane id -> (the lane's revision, its export); only exported lanes.
  std::unordered_map<std::uint64_t, std::pair<std::uint64_t, std::shared_ptr<const MapLane>>> lanes;
  // The metadata's quantiles of the front end's and the optimizer's timing series.
  SeriesQuantile<float> frontend_p50{0.5}, frontend_p95{0.95}, extraction_p50{0.5};
  SeriesQuantile<double> solve_p50{0.5}, solve_p95{0.95}, solve_max{1.0};
  // Chunks and lanes built anew by the last export (what it cost beyond the live markings).
  std::size_t chunks_built = 0, lanes_built = 0;

  // Forgets everything but the chunk size.
  void Clear() { *this = SnapshotCache(retired_chunk_slots); }
};

}  // namespace ipm_road_mapper
