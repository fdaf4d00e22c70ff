// What Mapper::ExportSnapshot keeps from one export to the next, so that the next one
// rebuilds only the parts that changed and shares the rest: the retired markings' chunks
// (copy-on-write: a chunk is rebuilt when one of its slots changed, found through the
// ChangeLog, never by scanning), each lane's export with the revision it was made at (its
// control points in chunks: a lane that changed from point i on rebuilds the chunks from
// the one holding i, found through the ChangeLog's lane ranges), and
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
  explicit SnapshotCache(std::size_t retired_chunk_slots = 64, std::size_t lane_chunk_points = 64)
      : retired_chunk_slots(retired_chunk_slots > 0 ? retired_chunk_slots : 1),
        lane_chunk_points(lane_chunk_points > 0 ? lane_chunk_points : 1) {}

  // Retired markings per chunk (> 0): chunk k exports retired slots [k * n, (k + 1) * n).
  std::size_t retired_chunk_slots;
  // Control points per lane chunk (> 0): chunk k holds points [k * n, (k + 1) * n).
  std::size_t lane_chunk_points;

  // The map's revision at the last export; 0: nothing cached (the next export builds all).
  std::uint64_t revision = 0;
  // The retired markings' count at the last export.
  std::size_t retired_count = 0;
  // The exported retired markings, one chunk per retired_chunk_slots slots.
  MarkingChunks retired_chunks;
  // Lane id -> (the lane's revision, its export); only exported lanes.
  std::unordered_map<std::uint64_t, std::pair<std::uint64_t, std::shared_ptr<const SharedLane>>>
      lanes;
  // The metadata's quantiles of the front end's and the optimizer's timing series.
  SeriesQuantile<float> frontend_p50{0.5}, frontend_p95{0.95}, extraction_p50{0.5};
  SeriesQuantile<double> solve_p50{0.5}, solve_p95{0.95}, solve_max{1.0};
  // Chunks and lanes built anew by the last export (what it cost beyond the live markings),
  // and the lanes' control points copied into new chunks.
  std::size_t chunks_built = 0, lanes_built = 0, lane_points_built = 0;

  // Forgets everything but the chunk sizes.
  void Clear() { *this = SnapshotCache(retired_chunk_slots, lane_chunk_points); }
};

}  // namespace ipm_road_mapper
