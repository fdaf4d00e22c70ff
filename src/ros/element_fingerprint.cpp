#include "ipm_road_mapper/ros/element_fingerprint.h"

#include <algorithm>
#include <functional>
#include <string>

namespace ipm_road_mapper {
namespace {

void HashClass(std::size_t* seed, int class_id, const std::string& class_name) {
  HashCombine(seed, std::hash<int>()(class_id));
  HashCombine(seed, std::hash<std::string>()(class_name));
}

void HashLife(std::size_t* seed, int observations, double first_seen, double last_seen) {
  HashCombine(seed, std::hash<int>()(observations));
  HashCombine(seed, std::hash<double>()(first_seen));
  HashCombine(seed, std::hash<double>()(last_seen));
}

}  // namespace

void HashCombine(std::size_t* seed, std::size_t value) {
  *seed ^= value + 0x9e3779b97f4a7c15ull + (*seed << 6) + (*seed >> 2);
}

void HashPoint(std::size_t* seed, const Eigen::Vector3d& p) {
  for (int i = 0; i < 3; ++i) HashCombine(seed, std::hash<double>()(p[i]));
}

std::size_t GeometryFingerprint(const MapMarking& marking) {
  std::size_t seed = 0;
  HashClass(&seed, marking.class_id, marking.class_name);
  for (const Eigen::Vector3d& c : marking.corners_map) HashPoint(&seed, c);
  return seed;
}

std::size_t GeometryFingerprint(const MapLane& lane, std::size_t first, std::size_t last) {
  std::size_t seed = 0;
  HashClass(&seed, lane.class_id, lane.class_name);
  last = std::min(last, lane.control_points_map.size());
  for (std::size_t i = first; i < last; ++i) HashPoint(&seed, lane.control_points_map[i]);
  return seed;
}

std::size_t MessageFingerprint(const MapMarking& marking) {
  std::size_t seed = GeometryFingerprint(marking);
  HashLife(&seed, marking.observations, marking.first_seen, marking.last_seen);
  return seed;
}

std::size_t MessageFingerprint(const MapLane& lane) {
  std::size_t seed = GeometryFingerprint(lane, 0, lane.control_points_map.size());
  HashCombine(&seed, FieldsFingerprint(lane));
  return seed;
}

std::size_t FieldsFingerprint(const MapLane& lane) {
  std::size_t seed = 0;
  HashClass(&seed, lane.class_id, lane.class_name);
  HashCombine(&seed, std::hash<std::string>()(lane.style));
  HashLife(&seed, lane.observations, lane.first_seen, lane.last_seen);
  // Not the unmeasured flags: a join sets them with the points it lays, so they change only
  // with their points, which the patch re-sends with them.
  // The topology: a new link re-sends the lane's fields (its patch carries the links).
  for (const auto* ids : {&lane.predecessors, &lane.successors}) {
    HashCombine(&seed, ids->size());
    for (const std::uint64_t id : *ids) HashCombine(&seed, std::hash<std::uint64_t>()(id));
  }
  return seed;
}

}  // namespace ipm_road_mapper
