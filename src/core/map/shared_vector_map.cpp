#include "ipm_road_mapper/core/map/shared_vector_map.h"

#include <algorithm>
#include <utility>

namespace ipm_road_mapper {

std::size_t SharedVectorMap::MarkingCount() const {
  std::size_t count = 0;
  for (const auto& chunk : marking_chunks) count += chunk->size();
  return count;
}

std::size_t SharedLane::PointCount() const {
  std::size_t count = 0;
  for (const auto& chunk : point_chunks) count += chunk->size();
  return count;
}

MapLane SharedLane::ToMapLane() const {
  MapLane lane = fields;
  lane.control_points_map.clear();
  lane.control_points_map.reserve(PointCount());
  for (const auto& chunk : point_chunks) {
    lane.control_points_map.insert(lane.control_points_map.end(), chunk->begin(), chunk->end());
  }
  return lane;
}

std::shared_ptr<SharedLane> ShareLane(MapLane lane, std::size_t chunk_points) {
  chunk_points = std::max<std::size_t>(chunk_points, 1);
  auto shared = std::make_shared<SharedLane>();
  const std::vector<Eigen::Vector3d>& points = lane.control_points_map;
  for (std::size_t first = 0; first < points.size(); first += chunk_points) {
    const std::size_t last = std::min(points.size(), first + chunk_points);
    shared->point_chunks.push_back(
        std::make_shared<const LanePointChunk>(points.begin() + first, points.begin() + last));
  }
  lane.control_points_map.clear();
  shared->fields = std::move(lane);
  return shared;
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
  for (const auto& lane : lanes) map.lanes.push_back(lane->ToMapLane());
  return map;
}

SharedVectorMap ShareVectorMap(VectorMap map) {
  SharedVectorMap shared;
  if (!map.markings.empty()) {
    shared.marking_chunks.push_back(std::make_shared<const MarkingChunk>(std::move(map.markings)));
  }
  for (MapLane& lane : map.lanes) shared.lanes.push_back(ShareLane(std::move(lane), 64));
  map.markings.clear();
  map.lanes.clear();
  shared.header = std::move(map);
  return shared;
}

}  // namespace ipm_road_mapper
