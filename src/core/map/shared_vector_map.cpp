#include "ipm_road_mapper/core/map/shared_vector_map.h"

#include <utility>

namespace ipm_road_mapper {

std::size_t SharedVectorMap::MarkingCount() const {
  std::size_t count = 0;
  for (const auto& chunk : marking_chunks) count += chunk->size();
  return count;
}

VectorMap SharedVectorMap::ToVectorMap() const {
  VectorMap map = header;
  map.markings.clear();
  map.markings.reserve(MarkingCount());
  for (const auto& chunk : marking_chunks) {
    map.markings.insert(map.markings.end(), chunk->begin(), chunk->end());
  }
  map.lanes.clear();
  map.lanes.reserve(lanes.size());
  for (const auto& lane : lanes) map.lanes.push_back(*lane);
  return map;
}

SharedVectorMap ShareVectorMap(VectorMap map) {
  SharedVectorMap shared;
  if (!map.markings.empty()) {
    shared.marking_chunks.push_back(std::make_shared<const MarkingChunk>(std::move(map.markings)));
  }
  for (MapLane& lane : map.lanes) {
    shared.lanes.push_back(std::make_shared<const MapLane>(std::move(lane)));
  }
  map.markings.clear();
  map.lanes.clear();
  shared.header = std::move(map);
  return shared;
}

}  // namespace ipm_road_mapper
