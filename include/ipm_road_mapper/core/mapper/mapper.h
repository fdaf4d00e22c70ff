// The core mapper: takes one FrameInput at a time (mask + camera + odometry pose at the
// mask stamp) and keeps the vectorized map. No ROS: the nodelet and the offline runner
// both drive it. Bad input is skipped and counted, never fatal, and never touches the map.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <map>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "ipm_road_mapper/core/backend/backend.h"
#include "ipm_road_mapper/core/frontend/class_table.h"
#include "ipm_road_mapper/core/backend/extrinsic_marginalization.h"
#include "ipm_road_mapper/core/backend/extrinsic_prior.h"
#include "ipm_road_mapper/core/geometry/ipm.h"
#include "ipm_road_mapper/core/mapper/mapper_options.h"
#include "ipm_road_mapper/core/geometry/pinhole_camera.h"
#include "ipm_road_mapper/core/map/road_map.h"
#include "ipm_road_mapper/core/geometry/road_surface.h"
#include "ipm_road_mapper/core/mapper/timing_series.h"
#include "ipm_road_mapper/core/map/vector_map.h"

namespace ipm_road_mapper {

// One camera frame as the core sees it (DESIGN.md §3).
struct FrameInput {
  double stamp = 0.0;       // s, the mask's stamp
  cv::Mat mask;             // CV_16UC1 instance mask, camera-sized
  CameraIntrinsics camera;  // from camera_info
  Eigen::Isometry3d T_map_base_odom = Eigen::Isometry3d::Identity();  // odometry at stamp
};

// What happened to a frame.
enum class FrameStatus { kUsed, kSkipped };

// Counters of everything the mapper did or refused, by reason (printed in summaries,
// published as diagnostics).
struct MapperCounters {
  std::uint64_t frames_received = 0;
  std::uint64_t frames_used = 0;
  std::map<std::string, std::uint64_t> frames_skipped;  // reason -> count
  ExtractionCounters extraction;
  std::uint64_t markings_created = 0;
  std::uint64_t lanes_created = 0;
  std::uint64_t spurious_dropped = 0;
  std::uint64_t lanes_merged = 0;
  std::uint64_t markings_merged = 0;
  std::uint64_t lane_observations_unused = 0;  // unmatched and too short / unfit to start a lane
  // Unmatched but close to a lane of its class (within twice the gates): not a new line, so
  // not started (a second spline along one line would be a duplicate).
  std::uint64_t lane_observations_near_lane = 0;
  std::uint64_t results_applied = 0;   // back-end results merged into the map
  std::uint64_t results_rejected = 0;  // unusable (solver failure, trust bound)
  std::uint64_t SkippedTotal() const;
};

// Wall time of the front end per used frame (mask -> observations -> map update; the
// back end's snapshot and merges excluded), for the summaries and the benchmark; the most
// recent frames only (timing_series.h).
struct FrontEndTiming {
  std::vector<float> extraction_ms;  // mask -> instances -> IPM measurements
  std::vector<float> total_ms;       // extraction + orientation, association, map update
};

// The mapper: the front end runs in the caller's thread; with options.backend.enabled it
// hands sliding windows to the back end (an owned optimizer thread, or inline when
// backend.synchronous) and merges its results at the start of the next frame.
class Mapper {
 public:
  Mapper(MapperOptions options, ClassTable classes, const Eigen::Isometry3d& T_base_cam_initial);
  ~Mapper();
  Mapper(Mapper&&) = default;

  // Processes one frame. On kSkipped, *reason (if given) says why, e.g. "bad_mask: mask is
  // 640x480, camera is 1280x720"; the counter of that reason is incremented.
  FrameStatus ProcessFrame(const FrameInput& input, std::string* reason = nullptr);

  // Counts a frame the caller could not even build (e.g. no odometry at its stamp).
  void CountSkipped(const std::string& reason);

  // End of input: solves the last window, waits for the optimizer and merges its results.
  void Finish();

  // The map as exported (map.json): every element seen at least twice (one seen once is
  // tentative until seen again or dropped as spurious). Lanes that no lane residual refines
  // are re-fit to all their selected pixels, re-IPMed with the current extrinsic and poses.
  VectorMap ExportMap() const;

  // Optimizer statistics (zeros without a back end).
  BackendStats backend_stats() const;

  // Drops the whole map and the frames, keeps options and extrinsic.
  void Reset();

  // Feeds a refined extrinsic forward (from the back end); used for the next frames' IPM.
  void SetExtrinsic(const Eigen::Isometry3d& T_base_cam) { T_base_cam_ = T_base_cam; }

  const RoadMap& map() const { return map_; }
  const MapperCounters& counters() const { return counters_; }
  const FrontEndTiming& frontend_timing() const { return frontend_timing_; }
  const MapperOptions& options() const { return options_; }
  const ClassTable& classes() const { return classes_; }
  const Eigen::Isometry3d& T_base_cam() const { return T_base_cam_; }
  const Eigen::Isometry3d& T_base_cam_initial() const { return T_base_cam_initial_; }

 private:
  std::string ValidateInput(const FrameInput& input) const;
  // Markings (mapper_markings.cpp). Re-fits each observation's rectangle with sides along the
  // road: the tangent of the nearest mapped lane (the ground truth's rectangles follow the
  // road; the vehicle's heading is 5 deg off on a 150 m curve 15 m ahead).
  void OrientMarkingsAlongRoad(const Ipm& ipm, const FrameRecord& frame,
                               std::vector<MarkingObservation>* markings);
  // Unit tangent of the mapped lane nearest to p_map (within 8 m); zero when there is none.
  Eigen::Vector3d RoadDirectionAt(const Eigen::Vector3d& p_map) const;
  void AddMarkings(const FrameObservations& observations, const FrameRecord& frame);
  // Merges elements of one class closer than association.marking_merge_distance_m.
  void MergeMarkings();
  // Lanes (mapper_lanes.cpp): association, start, growth, merging.
  void AddLanes(const FrameObservations& observations, const FrameRecord& frame);
  void StartLane(int class_id, const LaneMeasurement& measurement,
                 const std::vector<Eigen::Vector3d>& usable_map, const FrameRecord& frame);
  // Grows the lane's ends with this frame's usable points and refines them with the
  // selected points of its recent observations.
  void GrowLane(LaneElement* lane, std::size_t frame_index,
                const std::vector<Eigen::Vector3d>& usable_map) const;
  // Selected pixels of every observation of the lane, IPMed now and put in the map.
  std::vector<Eigen::Vector3d> SelectedPointsMap(const LaneElement& lane) const;
  // The lane's control points re-fit to all of SelectedPointsMap (export, merges).
  std::vector<Eigen::Vector3d> RefitControlPoints(const LaneElement& lane) const;
  bool LanesRefinedByBackend() const;
  // Back end (mapper_backend.cpp). A snapshot first retires what leaves the window: markings
  // no longer observed in it, whose information moves into the extrinsic prior (their
  // corners marginalized), and lane observations older than the lanes' context.
  WindowSnapshot BuildSnapshot();
  void RetireMarking(MarkingElement* marking);
  // End of input (backend.final_global_solve): one solve over the whole drive, so that what
  // retired while the extrinsic was still rough (markings, the poses that saw them) gets the
  // final extrinsic, and the windows' alternation converges where it was slow.
  void FinalGlobalSolve();
  // The road's plane at p_map from all the frames' poses (road_surface.h), and the sigma of
  // the road-surface prior there.
  RoadSurfaceEstimate RoadSurfaceAt(const Eigen::Vector3d& p_map) const;
  double RoadPriorSigma(const RoadSurfaceEstimate& road) const;
  void ApplyBackendResults();
  // Merges a result into the map; retired markings only with include_retired (the final
  // global solve: a window's late result must not move what its prior already holds).
  void ApplyResult(const WindowResult& result, bool include_retired);
  void MergeLanes();
  void DropSpurious(std::size_t frame_index);
  void Skip(const std::string& reason, std::string* out);

  MapperOptions options_;
  ClassTable classes_;
  Eigen::Isometry3d T_base_cam_initial_;
  Eigen::Isometry3d T_base_cam_;
  RoadMap map_;
  MapperCounters counters_;
  FrontEndTiming frontend_timing_;
  double last_stamp_ = -1.0;
  CameraIntrinsics camera_;  // of the last used frame
  std::uint64_t next_sequence_ = 1;
  std::unique_ptr<Backend> backend_;
  ExtrinsicPrior extrinsic_prior_;  // the mounting prior plus everything retired
};

}  // namespace ipm_road_mapper
