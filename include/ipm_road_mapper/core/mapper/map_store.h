// The mapper's map: the frames it used (with a spatial index over their positions), the live
// elements, the retired markings (with a spatial index over their centers), the lanes (with
// a spatial index over their control points), so that the front end's per-frame work touches
// the live elements and a neighbourhood only, and the
// road-geometry queries that the trackers and the window coordinator share (the road's
// direction and surface at a point). It owns the data; the trackers and the coordinator
// change it through the accessors.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "ipm_road_mapper/core/geometry/road_surface.h"
#include "ipm_road_mapper/core/map/road_map.h"
#include "ipm_road_mapper/core/mapper/change_log.h"
#include "ipm_road_mapper/core/mapper/frame_index.h"

namespace ipm_road_mapper {

class MapStore {
 public:
  // `road_plane_radius_m`: the radius of RoadSurfaceAt (backend.road_plane_radius_m).
  explicit MapStore(double road_plane_radius_m);

  // Appends a used frame; its corrected pose starts at the odometry (the front end places
  // its observations there, the pose prior pulls it there).
  const FrameRecord& AddFrame(double stamp, const Eigen::Isometry3d& T_map_base_odom,
                              const RoadPlane& ground_base = RoadPlane());
  // Sets frame `index`'s corrected pose (a back-end result).
  void SetFramePose(std::size_t index, const Eigen::Isometry3d& T_map_base);
  // Takes the correction fitted over `solved`, the frames a solve just moved
  // (odometry_correction.h), as the current one: the frames after the newest of them, which
  // no solve has reached yet, come out corrected by it (CorrectedPose). Empty: no change.
  void SetCorrectionFrom(const std::vector<std::size_t>& solved);
  // The current correction, T_map_odom: the corrected map frame from the odometry's frame
  // (identity until a solve moved a frame).
  const Eigen::Isometry3d& T_map_odom() const { return T_map_odom_; }
  // The frame T_map_odom() was taken from (-1: none yet).
  std::int64_t corrected_frame() const { return corrected_frame_; }
  // Frame `index`'s pose as it comes out (~corrected_odom, the exported trajectory): the
  // solved pose, or for a frame after the last solve's newest one the correction carried
  // along its odometry, T_map_odom() * T_map_base_odom. Not an input of the estimator: a
  // frame's own T_map_base stays the odometry until a solve moves it (placing the front
  // end's observations at the carried poses lets the map follow the correction and the
  // correction random-walk away from the odometry: 0.04 -> 0.66 m on public_road).
  Eigen::Isometry3d CorrectedPose(std::size_t index) const;
  // A fresh element id.
  std::uint64_t NewId() { return map_.next_id++; }
  // Moves the live markings flagged `retired` and last seen before `first_frame` into the
  // retired markings.
  void RetireMarkings(std::size_t first_frame);
  // Moves retired marking `retired_index` back among the live ones (re-observed) and returns
  // its live index. Invalidates retired indices (the last retired one takes its place).
  std::size_t ReviveMarking(std::size_t retired_index);
  // Re-indexes the retired markings after their corners changed (the final global solve).
  void ReindexRetiredMarkings();
  // Indices of the retired markings whose centers lie within radius_m of p_map (x-y),
  // sorted.
  std::vector<std::size_t> RetiredMarkingsNear(const Eigen::Vector3d& p_map, double radius_m) const;
  // The largest trace of a retired marking's center covariance (association's gate radius).
  double max_retired_cov_trace() const { return max_retired_cov_trace_; }

  // Drops the measurements of frames before `frame` from every element's history (counted
  // in `pruned`): what export and association need stays (corners, control points, spans).
  void PruneHistoriesBefore(std::size_t frame);
  // Drops every frame and element (ids keep counting; revisions too: ChangeLog::Clear).
  void Clear();

  // Change tracking (incremental export, map_changes.h). Every write of what an element's
  // exported form shows (created, grown, re-optimized, merged into, confirmed, retired)
  // calls Touch: the element gets a new revision, and a retired marking is logged so that
  // an export finds it without scanning the retired ones.
  void Touch(MarkingElement* marking);
  // A lane's Touch also logs the first of its control points the write may have changed
  // (ChangeLog::NoteLane): the default 0, the whole lane, is right for any writer, only
  // slower to publish; a writer that moved the points from index k on only passes k.
  void Touch(LaneElement* lane, std::size_t first_changed = 0);
  // Logs the live markings and lanes that left the map since the last call (merged away,
  // dropped as spurious or inconsistent, joined into another lane): the Mapper calls it at
  // the end of each step that may remove elements. Costs the live elements and lanes.
  void NoteRemovals();
  // The revisions and the logs of retirements and removals.
  const ChangeLog& changes() const { return changes_; }
  // Index of retired marking `id` in retired_markings(), or -1.
  std::int64_t RetiredIndexOf(std::uint64_t id) const;

  const RoadMap& map() const { return map_; }
  const std::vector<FrameRecord>& frames() const { return map_.frames; }
  std::vector<MarkingElement>& markings() { return map_.markings; }
  const std::vector<MarkingElement>& markings() const { return map_.markings; }
  // Markings that left the window (RetireMarkings); the front end looks them up by place.
  std::vector<MarkingElement>& retired_markings() { return map_.retired_markings; }
  const std::vector<MarkingElement>& retired_markings() const { return map_.retired_markings; }
  std::vector<LaneElement>& lanes() { return map_.lanes; }
  const std::vector<LaneElement>& lanes() const { return map_.lanes; }
  // Indices into lanes(), ascending, of every lane with a control point within radius_m of
  // p_map (x-y), and possibly a few more (a superset: the lanes of the grid cells the disc's
  // square touches). Lanes are never retired, so a loop over lanes() costs the whole drive's
  // lanes; a per-frame loop over these costs a neighbourhood. Every writer of a lane's
  // control points calls Touch, which indexes them.
  std::vector<std::size_t> LanesNear(const Eigen::Vector3d& p_map, double radius_m) const;

  // Unit tangent of the mapped lane nearest to p_map, within max_distance_m (8 m); zero when
  // there is none.
  Eigen::Vector3d RoadDirectionAt(const Eigen::Vector3d& p_map) const;
  // The road's plane at p_map from the frames that drove within the radius (RoadSurfaceNear's
  // rule, through the frame index). A point no frame passed within the radius (ahead of the
  // vehicle, or farther aside) gets the plane of the frames within the radius of the closest
  // frame instead of that one frame's plane: the road around the drive's closest point, not
  // one instant of the body's pitch on its suspension (0.13 deg of it put urban's far-only
  // crossing stripes, 7-8 m aside, 0.7 m off along the road). distance_m and lateral_m stay
  // the closest frame's. (The window's own surface prior keeps RoadSurfaceNear's closest
  // pose: there the average cost urban's lanes 0.057 -> 0.072 m, measured.)
  RoadSurfaceEstimate RoadSurfaceAt(const Eigen::Vector3d& p_map) const;
  // The radius of RoadSurfaceAt: a point farther from every frame gets an extrapolated plane.
  double road_plane_radius_m() const { return road_plane_radius_m_; }

  // A lane farther than this from a point does not give it the road's direction.
  static constexpr double kRoadDirectionMaxDistanceM = 8.0;

 private:
  using CellKey = std::int64_t;
  CellKey RetiredCellOf(const Eigen::Vector3d& p_map) const;
  void IndexRetired(std::size_t retired_index);
  // Lists `lane` in the lane cells of its control points from first_changed - 1 on.
  void IndexLane(const LaneElement& lane, std::size_t first_changed);

  // Whether `marking` is an element of retired_markings().
  bool IsRetired(const MarkingElement* marking) const;

  double road_plane_radius_m_;
  RoadMap map_;
  ChangeLog changes_;
  // Retired marking id -> index in retired_markings (kept with retired_cells_).
  std::unordered_map<std::uint64_t, std::size_t> retired_index_by_id_;
  // The live marking ids and the lane ids as of the last NoteRemovals.
  std::unordered_set<std::uint64_t> noted_marking_ids_, noted_lane_ids_;
  FrameIndex frame_index_;
  // Retired markings by the grid cell of their center (cells of kRetiredCellM).
  std::unordered_map<CellKey, std::vector<std::size_t>> retired_cells_;
  double max_retired_cov_trace_ = 0.0;
  // Lane ids by the grid cell (kLaneCellM) of their control points. An id is never removed
  // when its lane's points leave a cell (a superset), only when the lane has left the map
  // (LanesNear drops it then); lane_index_by_id_ is rebuilt when an id is not where it says.
  mutable std::unordered_map<CellKey, std::vector<std::uint64_t>> lane_cells_;
  mutable std::unordered_map<std::uint64_t, std::size_t> lane_index_by_id_;
  Eigen::Isometry3d T_map_odom_ = Eigen::Isometry3d::Identity();
  std::int64_t corrected_frame_ = -1;  // the frame T_map_odom_ was taken from (-1: none)
  static constexpr double kRetiredCellM = 10.0;
  static constexpr double kLaneCellM = 25.0;
  static constexpr double kMaxLaneQueryCells = 4096.0;  // a disc of radius 800 m
};

}  // namespace ipm_road_mapper
