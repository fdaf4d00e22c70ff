// The mapper's map: the frames it used (with a spatial index over their positions) and its
// elements, and the road-geometry queries that the trackers and the window coordinator
// share (the road's direction and surface at a point). It owns the data; the trackers and
// the coordinator change it through the accessors.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "ipm_road_mapper/core/geometry/road_surface.h"
#include "ipm_road_mapper/core/map/road_map.h"
#include "ipm_road_mapper/core/mapper/frame_index.h"

namespace ipm_road_mapper {

class MapStore {
 public:
  // `road_plane_radius_m`: the radius of RoadSurfaceAt (backend.road_plane_radius_m).
  explicit MapStore(double road_plane_radius_m);

  // Appends a used frame; its corrected pose starts at the odometry.
  const FrameRecord& AddFrame(double stamp, const Eigen::Isometry3d& T_map_base_odom);
  // Sets frame `index`'s corrected pose (a back-end result).
  void SetFramePose(std::size_t index, const Eigen::Isometry3d& T_map_base);
  // A fresh element id.
  std::uint64_t NewId() { return map_.next_id++; }
  // Drops the measurements of frames before `frame` from every element's history (counted
  // in `pruned`): what export and association need stays (corners, control points, spans).
  void PruneHistoriesBefore(std::size_t frame);
  // Drops every frame and element (ids keep counting).
  void Clear();

  const RoadMap& map() const { return map_; }
  const std::vector<FrameRecord>& frames() const { return map_.frames; }
  std::vector<MarkingElement>& markings() { return map_.markings; }
  const std::vector<MarkingElement>& markings() const { return map_.markings; }
  std::vector<LaneElement>& lanes() { return map_.lanes; }
  const std::vector<LaneElement>& lanes() const { return map_.lanes; }

  // Unit tangent of the mapped lane nearest to p_map, within max_distance_m (8 m); zero when
  // there is none.
  Eigen::Vector3d RoadDirectionAt(const Eigen::Vector3d& p_map) const;
  // The road's plane at p_map from the frames that drove within the radius
  // (RoadSurfaceNear's rule, through the frame index).
  RoadSurfaceEstimate RoadSurfaceAt(const Eigen::Vector3d& p_map) const;

  // A lane farther than this from a point does not give it the road's direction.
  static constexpr double kRoadDirectionMaxDistanceM = 8.0;

 private:
  double road_plane_radius_m_;
  RoadMap map_;
  FrameIndex frame_index_;
};

}  // namespace ipm_road_mapper
