// The core mapper: takes one FrameInput at a time (mask + camera + odometry pose at the
// mask stamp) and keeps the vectorized map. No ROS: the nodelet and the offline runner both
// drive it. Bad input is skipped and counted, never fatal, and never touches the map.
//
// A facade over the rooms that do the work, all sharing one MapStore:
//   MarkingTracker, LaneTracker   the front end's association, growth and merging
//   WindowCoordinator             windows to the back end, retirement, results, final solve
// The front end runs in the caller's thread; the back end in the Backend's owned thread.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <limits>
#include <opencv2/core.hpp>
#include <optional>
#include <string>

#include "ipm_road_mapper/core/backend/backend.h"
#include "ipm_road_mapper/core/frontend/class_table.h"
#include "ipm_road_mapper/core/geometry/pinhole_camera.h"
#include "ipm_road_mapper/core/map/shared_vector_map.h"
#include "ipm_road_mapper/core/map/vector_map.h"
#include "ipm_road_mapper/core/mapper/lane_tracker.h"
#include "ipm_road_mapper/core/mapper/map_changes.h"
#include "ipm_road_mapper/core/mapper/map_store.h"
#include "ipm_road_mapper/core/mapper/mapper_counters.h"
#include "ipm_road_mapper/core/mapper/mapper_options.h"
#include "ipm_road_mapper/core/mapper/marking_tracker.h"
#include "ipm_road_mapper/core/mapper/skip_reason.h"
#include "ipm_road_mapper/core/mapper/snapshot_cache.h"
#include "ipm_road_mapper/core/mapper/window_coordinator.h"

namespace ipm_road_mapper {

// One camera frame as the core sees it (docs/architecture.md).
struct FrameInput {
  double stamp = 0.0;       // s, the mask's stamp
  cv::Mat mask;             // CV_16UC1 instance mask, camera-sized
  CameraIntrinsics camera;  // from camera_info
  Eigen::Isometry3d T_map_base_odom = Eigen::Isometry3d::Identity();  // odometry at stamp
};

// A corrected vehicle pose with its covariance (pose_covariance.h: x y z, rotation about
// the map axes), as ~corrected_odom publishes it.
struct PoseEstimate {
  double stamp = 0.0;  // s
  Eigen::Isometry3d T_map_base = Eigen::Isometry3d::Identity();
  PoseCovariance covariance = PoseCovariance::Zero();
  // The correction at this frame, T_map_base * T_odom_base^-1 (REP-105 map -> odom): with
  // the frame's odometry it gives T_map_base.
  Eigen::Isometry3d T_map_odom = Eigen::Isometry3d::Identity();
};

// What happened to a frame.
enum class FrameStatus { kUsed, kSkipped };

// What an export holds beyond the elements.
struct ExportOptions {
  // The corrected trajectory's newest poses only (a live snapshot for ~corrected_path);
  // 0 = every pose (map files).
  std::size_t max_trajectory_poses = 0;
  // Link the lanes' predecessors and successors (LinkLaneTopology). Its cost grows with the
  // lanes' count times their length (0.6 s at 10 km): a live snapshot for publication, whose
  // messages carry no topology, skips it, and a save links it on its copy.
  bool lane_topology = true;
};

class Mapper {
 public:
  Mapper(MapperOptions options, ClassTable classes, const Eigen::Isometry3d& T_base_cam_initial);
  // The rooms hold pointers into the Mapper: neither copied nor moved.
  Mapper(const Mapper&) = delete;
  Mapper& operator=(const Mapper&) = delete;

  // Processes one frame. On kSkipped, *reason (if given) says why, e.g. "bad_mask: mask is
  // 640x480, camera is 1280x720"; the counter of that reason is incremented.
  FrameStatus ProcessFrame(const FrameInput& input, std::string* reason = nullptr);

  // Counts a frame the caller could not even build (e.g. no odometry at its stamp).
  void CountSkipped(SkipReason reason);
  // The same from a "<key>: <detail>" text (SkipText); a key that names no SkipReason is
  // counted under its own name.
  void CountSkipped(const std::string& text);

  // End of input: solves the last window, waits for the optimizer, merges its results and
  // runs the final global solve, within time_budget_s (the nodelet's unload budget; the
  // offline runner waits for all). True when all of it finished within the budget; the map
  // is usable either way.
  bool Finish(double time_budget_s = std::numeric_limits<double>::infinity());

  // The map as exported (map.json): every element seen at least twice (one seen once is
  // tentative until seen again or dropped as spurious). Lanes that no lane residual refines
  // are re-fit to all their selected pixels, re-IPMed with the current extrinsic and poses.
  VectorMap ExportMap(const ExportOptions& options = ExportOptions()) const;

  // The incremental export (map_changes.h): what ExportMap's elements changed after
  // revision `since` (0: all of them), and the ids it no longer exports. Costs the live
  // markings, the lanes and what changed; retired markings only when they changed; with
  // `options.lane_context_points` a changed lane costs its changed part, not its length.
  MapChanges ExportChanges(std::uint64_t since, const ChangesOptions& options = {}) const;
  // The live snapshot's export (what ExportMap gives with `max_trajectory_poses` newest
  // poses and no lane topology), in shared immutable storage: only the live markings, the
  // retired-marking chunks with a slot changed since the last call with `cache`, and the
  // lanes whose revision changed are built anew; the rest is `cache`'s, shared. Its cost
  // follows what changed, not the map's length (mapper_snapshot.cpp).
  SharedVectorMap ExportSnapshot(std::size_t max_trajectory_poses, SnapshotCache* cache) const;
  // The map's revision now (MapChanges::revision).
  std::uint64_t revision() const { return store_.changes().revision(); }

  // Optimizer statistics (zeros without a back end).
  BackendStats backend_stats() const { return windows_.stats(); }

  // Drops the whole map and the frames, keeps options and extrinsic.
  void Reset();

  const RoadMap& map() const { return store_.map(); }
  const MapperCounters& counters() const { return counters_; }
  const FrontEndTiming& frontend_timing() const { return frontend_timing_; }
  const MapperOptions& options() const { return options_; }
  const ClassTable& classes() const { return classes_; }
  // The extrinsic the front end uses now: the refined one once the back end has a result.
  const Eigen::Isometry3d& T_base_cam() const { return windows_.T_base_cam(); }
  const Eigen::Isometry3d& T_base_cam_initial() const { return T_base_cam_initial_; }
  // The refined extrinsic's covariance (roll, pitch, yaw about base_link in rad, x, y, z in
  // m) and the axes the data has observed (window_coordinator.h).
  const Eigen::Matrix<double, 6, 6>& T_base_cam_covariance() const {
    return windows_.T_base_cam_covariance();
  }
  const std::array<bool, 6>& extrinsic_observed() const { return windows_.extrinsic_observed(); }
  // The newest used frame's corrected pose: until a solve reaches it, the solved trajectory
  // continued over the frames since with the motion and odometry priors
  // (pose_extrapolator.h; T_map_odom() * its odometry when that cannot run); nullopt before
  // a frame.
  std::optional<PoseEstimate> NewestPose() const;
  // The correction of the odometry, T_map_odom (REP-105 map -> odom): identity until a
  // solve corrected a frame; then T_map_base_opt * T_odom_base_opt^-1 of the newest frame
  // the last solve moved; T_map_odom() * odometry is a later frame's carried pose
  // (MapStore::CorrectedPose, the exported trajectory). The correction at the newest frame,
  // what the nodelet broadcasts, is NewestPose()->T_map_odom.
  const Eigen::Isometry3d& T_map_odom() const { return store_.T_map_odom(); }

 private:
  // Why an input cannot be used.
  struct Invalid {
    SkipReason reason;
    std::string detail;
  };
  std::optional<Invalid> ValidateInput(const FrameInput& input) const;
  // Drops the measurements older than the final solve's span (backend.final_global_max_frames
  // frames) from the histories: no later step reads them, and memory then grows with the
  // map, not with the frames seen.
  void PruneHistories();
  // ExportMap's form of one element: false when export skips it (tentative, seen once).
  bool ExportMarking(const MarkingElement& element, MapMarking* marking) const;
  // A lane's control points from index `from` on only (a tail for ExportChanges).
  bool ExportLane(const LaneElement& element, MapLane* lane, std::size_t from = 0) const;
  // The exported name of class `class_id` ("class_<id>" when the table has none).
  std::string ClassName(int class_id) const;
  // The extrinsic fields of an export.
  void ExportExtrinsic(VectorMap* out) const;
  // Every field of an export but its elements: the extrinsic, the trajectory's newest
  // `max_trajectory_poses` poses (0: all) and the metadata, its timing quantiles through
  // `cache` when given (the same values, at the cost of the samples added since).
  void ExportHeader(std::size_t max_trajectory_poses, SnapshotCache* cache, VectorMap* out) const;

  // Declaration order is construction order: the rooms hold pointers to what precedes them.
  const MapperOptions options_;
  const ClassTable classes_;
  const Eigen::Isometry3d T_base_cam_initial_;
  MaskSanity sanity_;  // before extraction: area classes out, merged lanes split, flicker
  MapperCounters counters_;
  FrontEndTiming frontend_timing_;
  MapStore store_;
  MarkingTracker markings_;
  LaneTracker lanes_;
  WindowCoordinator windows_;  // last: destroyed first, joining the optimizer thread
  double last_stamp_ = -1.0;
};

}  // namespace ipm_road_mapper
