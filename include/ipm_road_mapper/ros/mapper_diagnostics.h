// The nodelet's diagnostics (diagnostic_updater, on /diagnostics): four statuses,
//   "<node>: inputs"    rates of masks, camera_info, synchronized pairs, odometry, images;
//   "<node>: frames"    frames received / used / skipped by reason, masks dropped by the
//                       sync (no camera_info), masks and odometry lost before their
//                       callbacks (subscriber queue full: seq / stamp gaps), odometry
//                       counters, callback and publication cost;
//   "<node>: optimizer" windows submitted / solved / dropped / unusable, solve time;
//   "<node>: extrinsic" where the rough extrinsic came from, and how far the refined one
//                       moved from it;
//   "<node>: saves"     the ros/save_map_path saves (autosave, shutdown): the last one's
//                       wall time, age and status (ok / the error).
// The status functions are pure (snapshot -> DiagnosticStatusWrapper) and unit-tested.
#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/node_handle.h>

#include <Eigen/Geometry>
#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "ipm_road_mapper/core/backend/backend.h"
#include "ipm_road_mapper/core/mapper/mapper.h"
#include "ipm_road_mapper/pipeline/frame_assembler.h"
#include "ipm_road_mapper/ros/input_gap_counter.h"

namespace ipm_road_mapper {

// Inputs whose arrivals are counted.
enum class MapperInput { kMask, kCameraInfo, kPair, kOdometry, kImage };
constexpr std::size_t kMapperInputCount = 5;

// Input arrivals since start and their rates over the last diagnostics period.
struct InputStats {
  std::array<std::uint64_t, kMapperInputCount> totals{};
  std::array<double, kMapperInputCount> rates_hz{};
};

// The saves to ros/save_map_path so far (MapSaver).
struct MapSaveStatus {
  std::string path;                // ros/save_map_path; "" = saving is off
  double autosave_period_s = 0.0;  // 0 = at shutdown only
  std::uint64_t saves = 0, failures = 0;
  double last_wall_time = 0.0;  // UNIX time (s) of the last attempt; 0 = none yet
  bool last_ok = false;
  std::string last_status;  // "ok: <files>" or the error of the last attempt
};

// The mapper's state as the diagnostics see it, copied under the nodelet's lock.
struct MapperStatusSnapshot {
  bool started = false;
  std::string extrinsic_status;  // the source when started, else why it is missing
  MapperCounters counters;       // of the Mapper (empty before start)
  std::map<std::string, std::uint64_t> skipped_before_start;
  FrameAssemblerCounters assembler;
  bool backend_enabled = false;
  BackendStats backend;
  Eigen::Isometry3d T_base_cam_initial = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d T_base_cam = Eigen::Isometry3d::Identity();
  // Its covariance (roll, pitch, yaw in rad, x, y, z in m) and the axes the data observed.
  Eigen::Matrix<double, 6, 6> T_base_cam_covariance = Eigen::Matrix<double, 6, 6>::Zero();
  std::array<bool, 6> extrinsic_observed{};
  // Marking classes whose views mostly exceed their size bounds (class_size_check.h), one
  // line each: the class table may not be the masks' own.
  std::vector<std::string> class_table_warnings;
  std::uint64_t callbacks = 0;                                       // data callbacks timed
  double callback_mean_ms = 0.0, callback_max_ms = 0.0;              // every data callback
  double frame_callback_mean_ms = 0.0, frame_callback_max_ms = 0.0;  // mask + camera_info ones
  std::array<std::uint64_t, 3> inputs_dropped{};  // input queue full: frames, odometry, images
  std::uint64_t publishes = 0;                    // map publications (timer cycles that sent)
  double publish_cpu_last_ms = 0.0, publish_cpu_mean_ms = 0.0, publish_cpu_max_ms = 0.0;
  std::size_t publish_last_markers = 0;         // the last publication's ~markers entries
  std::size_t publish_last_delta_elements = 0;  // ... ~vector_map_delta elements and ids
  std::size_t publish_last_bytes = 0;           // ... serialized bytes of all its messages
  // Subscriber queues (ros/sync_queue_size, ros/odom_queue_size) and the messages that never
  // reached the callbacks, told by header seq / stamp gaps (InputGapCounter).
  int mask_queue_size = 0, odom_queue_size = 0;
  InputGapStats mask_gaps, odometry_gaps;
  MapSaveStatus save;
};

// The statuses (see the file comment). `previous` is the snapshot of the last update,
// to tell what happened during the period (levels: WARN when frames arrived but none was
// used, or the optimizer rejected a result since the last update).
void FillInputStatus(const InputStats& inputs, diagnostic_updater::DiagnosticStatusWrapper* s);
void FillFrameStatus(const MapperStatusSnapshot& now, const MapperStatusSnapshot& previous,
                     const InputStats& inputs, diagnostic_updater::DiagnosticStatusWrapper* s);
void FillOptimizerStatus(const MapperStatusSnapshot& now, const MapperStatusSnapshot& previous,
                         diagnostic_updater::DiagnosticStatusWrapper* s);
void FillExtrinsicStatus(const MapperStatusSnapshot& now,
                         diagnostic_updater::DiagnosticStatusWrapper* s);
// `wall_now`: UNIX time (s), for the age of the last save. ERROR while the last save failed.
void FillSaveStatus(const MapSaveStatus& save, double wall_now,
                    diagnostic_updater::DiagnosticStatusWrapper* s);

// Owns the Updater; Count() may be called from any thread.
class MapperDiagnostics {
 public:
  MapperDiagnostics(ros::NodeHandle& nh, ros::NodeHandle& private_nh, const std::string& name,
                    std::function<MapperStatusSnapshot()> snapshot);

  void Count(MapperInput input) { ++counts_[static_cast<std::size_t>(input)]; }

  // Computes the rates, takes one snapshot and publishes (whatever ROS time does: the bag
  // may be paused).
  void Update();

 private:
  std::function<MapperStatusSnapshot()> snapshot_fn_;
  diagnostic_updater::Updater updater_;
  std::array<std::atomic<std::uint64_t>, kMapperInputCount> counts_{};
  std::mutex mutex_;  // below
  InputStats inputs_;
  MapperStatusSnapshot now_, previous_;
  std::chrono::steady_clock::time_point last_update_;
};

}  // namespace ipm_road_mapper
