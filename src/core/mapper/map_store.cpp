#include "ipm_road_mapper/core/mapper/map_store.h"

#include <algorithm>

#include "ipm_road_mapper/core/geometry/catmull_rom_spline.h"

namespace ipm_road_mapper {

MapStore::MapStore(double road_plane_radius_m)
    : road_plane_radius_m_(road_plane_radius_m),
      // Cells of the radius: a query looks at 3x3 cells at most.
      frame_index_(road_plane_radius_m > 0.0 ? road_plane_radius_m : 1.0) {}

const FrameRecord& MapStore::AddFrame(double stamp, const Eigen::Isometry3d& T_map_base_odom) {
  FrameRecord frame;
  frame.index = map_.frames.size();
  frame.stamp = stamp;
  frame.T_map_base_odom = T_map_base_odom;
  frame.T_map_base = T_map_base_odom;
  frame_index_.Set(frame.index, frame.T_map_base.translation());
  map_.frames.push_back(frame);
  return map_.frames.back();
}

void MapStore::SetFramePose(std::size_t index, const Eigen::Isometry3d& T_map_base) {
  map_.frames[index].T_map_base = T_map_base;
  frame_index_.Set(index, T_map_base.translation());
}

namespace {

// Erases the measurements of frames before `frame` (histories are sorted by frame).
template <typename Element>
void PruneBefore(std::size_t frame, Element* e) {
  auto keep = std::lower_bound(
      e->history.begin(), e->history.end(), frame,
      [](const auto& measurement, std::size_t f) { return measurement.frame_index < f; });
  const std::size_t n = static_cast<std::size_t>(keep - e->history.begin());
  if (n == 0) return;
  e->history.erase(e->history.begin(), keep);
  e->history.shrink_to_fit();
  e->pruned += n;
}

}  // namespace

void MapStore::PruneHistoriesBefore(std::size_t frame) {
  for (MarkingElement& m : map_.markings) PruneBefore(frame, &m);
  for (LaneElement& l : map_.lanes) PruneBefore(frame, &l);
}

void MapStore::Clear() {
  const std::uint64_t next_id = map_.next_id;
  map_ = RoadMap();
  map_.next_id = next_id;
  frame_index_.Clear();
}

Eigen::Vector3d MapStore::RoadDirectionAt(const Eigen::Vector3d& p_map) const {
  double best = kRoadDirectionMaxDistanceM;
  Eigen::Vector3d tangent_map = Eigen::Vector3d::Zero();
  for (const LaneElement& lane : map_.lanes) {
    std::size_t first = 0, last = 0;  // the lane's part near p_map only
    if (!ControlPointRangeNear(lane.control_points_map, {p_map}, kRoadDirectionMaxDistanceM + 5.0,
                               &first, &last)) {
      continue;
    }
    const CatmullRomSpline spline(std::vector<Eigen::Vector3d>(
        lane.control_points_map.begin() + first, lane.control_points_map.begin() + last + 1));
    const CatmullRomSpline::ClosestPoint closest = spline.FindClosest(p_map);
    if (closest.distance_m >= best) continue;
    best = closest.distance_m;
    tangent_map = spline.Derivative(closest.s);
  }
  return tangent_map.norm() > 0.0 ? tangent_map.normalized() : tangent_map;
}

RoadSurfaceEstimate MapStore::RoadSurfaceAt(const Eigen::Vector3d& p_map) const {
  std::size_t closest = 0;
  double closest_distance_m = 0.0;
  if (!frame_index_.Nearest(p_map, &closest, &closest_distance_m)) return RoadSurfaceEstimate();
  std::vector<const Eigen::Isometry3d*> within;
  for (std::size_t i : frame_index_.Within(p_map, road_plane_radius_m_)) {
    within.push_back(&map_.frames[i].T_map_base);
  }
  return RoadSurfaceFromPoses(within, map_.frames[closest].T_map_base, closest_distance_m);
}

}  // namespace ipm_road_mapper
