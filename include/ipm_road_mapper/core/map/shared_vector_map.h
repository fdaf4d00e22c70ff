// A VectorMap whose elements live in immutable storage that successive exports share: the
// markings in chunks, each lane's control points in chunks, each behind a
// shared_ptr<const ...>. An export
// that rebuilds only what changed and re-uses the pointers of the rest (Mapper::ExportSnapshot)
// then costs what changed, not what the map holds; ToVectorMap copies it all for a save or
// a full message. Immutable once built, so any thread may read it.
#pragma once

#include <cstddef>
#include <memory>
#include <vector>

#include "ipm_road_mapper/core/map/vector_map.h"

namespace ipm_road_mapper {

// One immutable run of exported markings.
using MarkingChunk = std::vector<MapMarking>;
// Marking chunks in export order, shared between exports.
using MarkingChunks = std::vector<std::shared_ptr<const MarkingChunk>>;
// One immutable run of a lane's control points.
using LanePointChunk = std::vector<Eigen::Vector3d>;

// A lane whose control points are in chunks that successive exports share: a lane as long
// as the drive that changed near its end rebuilds its last chunks only.
struct SharedLane {
  MapLane fields;  // every field of the lane but its control points (left empty)
  std::vector<std::shared_ptr<const LanePointChunk>> point_chunks;  // the points, in order

  // The control points' count over every chunk.
  std::size_t PointCount() const;
  // The whole lane: its fields with every control point copied in.
  MapLane ToMapLane() const;
};

// Lanes in export order, shared between exports.
using SharedLanes = std::vector<std::shared_ptr<const SharedLane>>;

// A shared lane holding `lane`'s control points in chunks of `chunk_points` (> 0).
std::shared_ptr<SharedLane> ShareLane(MapLane lane, std::size_t chunk_points);

struct SharedVectorMap {
  // Every field of the map but its elements (frame, extrinsic, trajectory, metadata, origin);
  // its `markings` and `lanes` stay empty.
  VectorMap header;
  MarkingChunks marking_chunks;  // the markings: the chunks' elements in order
  SharedLanes lanes;

  // The markings' count over every chunk.
  std::size_t MarkingCount() const;
  // The whole map: the header with every marking and lane copied in, in order.
  VectorMap ToVectorMap() const;
};

// A shared map holding `map`'s elements (one chunk of markings), e.g. for a test or a
// caller that has a plain map.
SharedVectorMap ShareVectorMap(VectorMap map);

}  // namespace ipm_road_mapper
