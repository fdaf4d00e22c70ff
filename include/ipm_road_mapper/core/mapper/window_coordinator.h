// The mapper's side of the back end: every backend.solve_every_n_frames frames it builds a
// window snapshot (retiring first what leaves the window: markings no longer observed in
// it, whose information moves into the extrinsic prior with their corners marginalized, and
// lane observations older than the lanes' context), hands it to the Backend (an owned
// optimizer thread, or inline when backend.synchronous), and merges the results into the
// map at the start of the next frame (window_coordinator_snapshot, _retire, _apply.cpp). It holds
// the refined extrinsic the front end's IPM uses (fed forward) and, at the end of input, runs the
// final global solve.
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <limits>
#include <memory>

#include "ipm_road_mapper/core/backend/backend.h"
#include "ipm_road_mapper/core/backend/extrinsic_prior.h"
#include "ipm_road_mapper/core/geometry/pinhole_camera.h"
#include "ipm_road_mapper/core/mapper/map_store.h"
#include "ipm_road_mapper/core/mapper/mapper_counters.h"
#include "ipm_road_mapper/core/mapper/mapper_options.h"
#include "ipm_road_mapper/core/mapper/window_lane_slice.h"  // LaneContextStart

namespace ipm_road_mapper {

class WindowCoordinator {
 public:
  // Starts the Backend when options.backend.enabled. The store and counters outlive it.
  WindowCoordinator(const MapperOptions& options, const Eigen::Isometry3d& T_base_cam_initial,
                    MapStore* store, MapperCounters* counters);
  // Stops the Backend (its thread is joined).
  ~WindowCoordinator();
  WindowCoordinator(const WindowCoordinator&) = delete;
  WindowCoordinator& operator=(const WindowCoordinator&) = delete;

  bool enabled() const { return backend_ != nullptr; }
  // Whether a lane residual refines the lanes' control points (else export re-fits them).
  bool LanesRefined() const;

  // Merges every result the optimizer has published since the last call.
  void ApplyResults();
  // After a used frame: submits a window every backend.solve_every_n_frames used frames.
  // `camera` is the frame's (the snapshot's camera).
  void OnFrameUsed(std::uint64_t frames_used, const CameraIntrinsics& camera);
  // End of input: solves the last window, waits for it, merges it, then the final global
  // solve (backend.final_global_solve), all within time_budget_s: a solve still running
  // when it runs out is not waited for, and the global solve gets what is left. True when
  // everything finished within the budget.
  bool Finish(double time_budget_s = std::numeric_limits<double>::infinity());
  // Drops pending windows (their results belong to the old map) and restarts the Backend.
  // The extrinsic and what is known about it belong to the vehicle: kept.
  void Reset();

  // The extrinsic the front end uses: the rough one until a result refines it.
  const Eigen::Isometry3d& T_base_cam() const { return T_base_cam_; }
  // Its covariance (roll, pitch, yaw about base_link in rad, x, y, z in m; the mounting
  // prior's until a result refines it) and the axes the data has observed.
  const Eigen::Matrix<double, 6, 6>& T_base_cam_covariance() const { return extrinsic_covariance_; }
  const std::array<bool, 6>& extrinsic_observed() const { return observed_; }
  BackendStats stats() const;
  // The covariance of frame `index`'s corrected pose (pose_covariance.h): the last solve's
  // covariance of its newest optimized frame carried along the odometry to it, plus the
  // frame's own odometry noise (backend.pose_prior_sigma_*) when no solve has reached it;
  // that noise alone before the first solve or without a back end.
  PoseCovariance PoseCovarianceOf(std::size_t index) const;
  // The camera of the last used frame (the snapshots', and the export re-fit's).
  const CameraIntrinsics& camera() const { return camera_; }
  // What the final global solve solves (Finish): the last backend.final_global_max_frames
  // frames free, every marking that reached the back end (retired ones too) and every lane
  // with their observations in that span, the extrinsic under the mounting prior alone and
  // started at the mounting value (backend.final_global_from_mounting) or where the windows
  // left it. Takes a sequence number.
  WindowSnapshot BuildGlobalSnapshot();

 private:
  // The first frame of the current window.
  std::size_t WindowStart() const;
  WindowSnapshot BuildSnapshot();
  void RetireMarking(MarkingElement* marking);
  // One solve over the whole drive, so that what retired while the extrinsic was still
  // rough (markings, the poses that saw them) gets the final extrinsic, and the windows'
  // alternation converges where it was slow.
  void FinalGlobalSolve(double time_budget_s);
  // Merges a result into the map; retired markings only with include_retired (the final
  // global solve: a window's late result must not move what its prior already holds).
  void ApplyResult(const WindowResult& result, bool include_retired);
  // The sigma of the road-surface prior at a road estimate.
  double RoadPriorSigma(const RoadSurfaceEstimate& road) const;

  const MapperOptions& options_;
  const Eigen::Isometry3d T_base_cam_initial_;
  Eigen::Isometry3d T_base_cam_;
  MapStore* store_;
  MapperCounters* counters_;
  CameraIntrinsics camera_;  // of the last used frame
  std::uint64_t next_sequence_ = 1;
  ExtrinsicPrior extrinsic_prior_;  // the mounting prior plus everything retired
  Eigen::Matrix<double, 6, 6> extrinsic_covariance_;
  std::array<bool, 6> observed_{};
  std::int64_t pose_covariance_frame_ = -1;  // the frame of pose_covariance_ (-1: none yet)
  PoseCovariance pose_covariance_ = PoseCovariance::Zero();
  std::unique_ptr<Backend> backend_;
};

}  // namespace ipm_road_mapper
