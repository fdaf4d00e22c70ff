// The nodelet's mapping thread. It owns the MappingSession (FrameAssembler + core Mapper):
// data callbacks Push() converted inputs into a bounded queue (the oldest dropped and
// counted when full) and never wait for it; the thread pops them, runs the session, and at
// most at ros/publish_rate_hz exports the map into an immutable MapSnapshot that it swaps
// in under a mutex held only for the pointer swap. Publishing, diagnostics and ~save_map
// read Latest(). ~reset and the shutdown Finish are commands the thread executes. Started
// in the constructor, stopped by flag + notify + join (Stop, the destructor); never
// detached. The core optimizer is the Mapper's own thread, joined by its destructor.
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "ipm_road_mapper/core/map/shared_vector_map.h"
#include "ipm_road_mapper/core/map/vector_map.h"
#include "ipm_road_mapper/core/mapper/snapshot_cache.h"
#include "ipm_road_mapper/pipeline/bounded_input_queue.h"
#include "ipm_road_mapper/pipeline/extrinsic_source.h"
#include "ipm_road_mapper/pipeline/frozen_trajectory.h"
#include "ipm_road_mapper/pipeline/mapper_config.h"
#include "ipm_road_mapper/pipeline/mapping_session.h"
#include "ipm_road_mapper/ros/mapper_diagnostics.h"
#include "ipm_road_mapper/ros/mapper_inputs.h"

namespace ipm_road_mapper {

// What the timers and services read; immutable once swapped in. Its cost does not grow with
// the drive: `map`'s elements sit in shared immutable storage (Mapper::ExportSnapshot: a
// snapshot rebuilds only the parts that changed since the previous one), its header holds
// only the newest poses of the trajectory (those a solve may still correct, at least
// ros/path_max_poses), the older ones are the frozen chunks that every snapshot shares;
// FullMap() joins them for a save.
struct MapSnapshot {
  // With the nodelet's frame and metadata in its header; nullptr before start.
  std::shared_ptr<const SharedVectorMap> map;
  TrajectoryChunks trajectory_prefix;  // the poses before map->header.trajectory
  std::uint64_t map_version = 0;       // changes whenever the map may have changed
  // The core's changes of `map` since the revision the publisher last acknowledged
  // (MappingWorker::Published; everything before that): what the delta and the changed
  // markers are built from. nullptr before start.
  std::shared_ptr<const MapChanges> changes;
  std::uint64_t resets = 0;         // ~resets before this map (its generation)
  double newest_frame_stamp = 0.0;  // of the newest used frame (s)
  std::string map_frame = "map";
  std::string refined_camera_frame;  // tf child of the refined extrinsic ("" before start)
  MapperStatusSnapshot status;       // the session's counters for the diagnostics

  // The map with its whole trajectory and the lanes' topology (a copy: what a save writes;
  // `map` has no topology, which no message carries); nullptr without a map.
  std::shared_ptr<const VectorMap> FullMap() const;
};

// What the mapping thread hands the nodelet after a frame was used.
struct FrameOutputs {
  // The newest used frame's corrected pose and its covariance (x y z, rotation about the
  // map axes: nav_msgs/Odometry's convention), ~corrected_odom.
  Eigen::Isometry3d T_map_base = Eigen::Isometry3d::Identity();
  PoseCovariance T_map_base_covariance = PoseCovariance::Zero();
  // The current correction of the odometry (REP-105 map -> odom).
  Eigen::Isometry3d T_map_odom = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d T_base_cam = Eigen::Isometry3d::Identity();
  std::string map_frame, odom_frame, base_frame;
  std::shared_ptr<const VectorMap> overlay_map;  // set when a debug overlay is due
};

class MappingWorker {
 public:
  using Clock = std::chrono::steady_clock;
  // Called in the mapping thread; must not block (publishing is fine).
  struct Hooks {
    std::function<void(const SessionUpdate&, const FrameOutputs&)> on_update;
    std::function<void(const sensor_msgs::ImageConstPtr&)> on_image;  // ~debug_image input
    std::function<bool()> overlay_wanted;                             // ~debug_image watched
  };

  // Starts the mapping thread. `lookup` is the non-blocking tf lookup of the extrinsic.
  MappingWorker(const MapperConfig& config, const ClassTable& classes, std::string node_name,
                TransformLookup lookup, Hooks hooks);
  // Stop().
  ~MappingWorker();

  // From any data callback: queues the item; never waits for the mapping thread.
  void Push(MapperInputItem item);

  // The newest snapshot (never nullptr).
  std::shared_ptr<const MapSnapshot> Latest() const;

  // From the publisher, after it published snapshot `resets` / `revision`
  // (changes->revision): later snapshots carry the changes since then. Never blocks on the
  // mapping thread.
  void Published(std::uint64_t resets, std::uint64_t revision);

  // Items dropped because the queue was full, per InputKind.
  std::array<std::uint64_t, kInputKindCount> dropped() const;

  // Asks the mapping thread to reset the session and waits up to `timeout_s`; false (and
  // *message says why) on a time-out, in which case a reset not yet begun is cancelled.
  bool Reset(double timeout_s, std::string* message);

  // No more pushes (later ones are ignored); a waiting Reset answers at once.
  void CloseInputs();

  // End of input: no more pushes; the thread maps what is queued until `deadline`, then
  // (if time is left) runs MappingSession::Finish with the rest and exports the map. Waits
  // until then, or at most kFinishGrace past `deadline`; returns the finished map
  // (*finished = true) or else the latest snapshot's map (FullMap), which holds every frame
  // the thread used; nullptr when the session never started.
  std::shared_ptr<const VectorMap> Finish(Clock::time_point deadline, bool* finished);

  // How long past its deadline Finish waits for the thread to hand over its map (one frame,
  // or the final solve's export; ros/shutdown_budget_s + 1 s is the unload's bound).
  static constexpr std::chrono::milliseconds kFinishGrace{500};

  // Stops and joins the mapping thread (idempotent); queued inputs are discarded.
  void Stop();

 private:
  void Run();
  void Handle(MapperInputItem& item);
  void HandleFrame(FrameItem& frame);
  void HandleOdometry(const OdometryItem& odometry);
  bool EnsureStarted(const std::string& camera_frame);
  void AfterUpdate(const SessionUpdate& update);
  // Makes and swaps in a snapshot; re-exports the map only when it changed.
  void Export();
  // Runs the pending ~reset; true when the thread is to end (stop or finish done).
  bool RunCommands();
  void RunFinish(Clock::time_point deadline);
  // The snapshot's map: the elements through snapshot_cache_, the trajectory after the frozen
  // prefix (freezing more of what no window solve changes any more).
  std::shared_ptr<const SharedVectorMap> ExportSnapshotMap();
  // The finished map: every element, the whole trajectory exported afresh, the topology.
  std::shared_ptr<const VectorMap> ExportFinishedMap() const;
  // The nodelet's frame and metadata on an export.
  void Label(VectorMap* map) const;
  MapperStatusSnapshot Status() const;

  const MapperConfig config_;
  const std::string node_name_;
  const TransformLookup lookup_;
  const Hooks hooks_;
  const Clock::duration export_period_, overlay_period_;

  // Mapping thread only.
  MappingSession session_;
  std::string camera_frame_, extrinsic_status_;
  bool odom_frame_checked_ = false;  // the odometry's frame was compared with ros/odom_frame
  std::string refined_frame_;
  std::uint64_t map_version_ = 0, exported_version_ = 0;
  std::uint64_t generation_ = 0;  // resets run
  bool status_dirty_ = true;
  double newest_frame_stamp_ = 0.0;
  std::shared_ptr<const SharedVectorMap> exported_map_;
  std::shared_ptr<const MapChanges> exported_changes_;  // of exported_map_
  SnapshotCache snapshot_cache_;                        // what exported_map_ shares
  FrozenTrajectory frozen_trajectory_;                  // the poses no solve changes any more
  TrajectoryChunks exported_prefix_;  // frozen_trajectory_'s chunks as of exported_map_
  Clock::time_point next_export_, last_overlay_;

  BoundedInputQueue<MapperInputItem> queue_;
  std::array<std::atomic<std::uint64_t>, kInputKindCount> dropped_{};

  std::mutex published_mutex_;  // held only to read / write the two below
  std::uint64_t published_resets_ = 0, published_revision_ = 0;

  mutable std::mutex snapshot_mutex_;  // held only to swap / copy the pointer
  std::shared_ptr<const MapSnapshot> latest_;

  std::mutex command_mutex_;  // the commands below
  std::condition_variable command_done_;
  bool stop_ = false, inputs_closed_ = false;
  bool reset_requested_ = false, reset_running_ = false;
  std::uint64_t resets_done_ = 0;
  bool finish_requested_ = false, finish_done_ = false;
  bool finish_past_budget_ = false;  // the queue took the budget: Latest() is the map
  Clock::time_point finish_deadline_;
  std::shared_ptr<const VectorMap> finished_map_;

  std::thread thread_;  // last: started after everything above exists
};

}  // namespace ipm_road_mapper
