// The nodelet's saves to ros/save_map_path. An owned saver thread writes the latest map
// snapshot every ros/autosave_period_s (wall time; only when the map changed), so a crash
// loses at most one period; it is never the data callbacks' or the mapping thread's. It
// also waits for SIGINT (SigintHook) and then runs the nodelet's final save while roscpp
// can still log. Every save goes through one MapSaveTarget (a map made after a ~reset
// that is smaller than the last save goes to <stem>_reset<N>.json) and SaveMapFiles
// (atomic). Stop() joins the thread; the destructor stops it.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "ipm_road_mapper/pipeline/map_files.h"
#include "ipm_road_mapper/ros/mapper_diagnostics.h"
#include "ipm_road_mapper/ros/mapping_worker.h"
#include "ipm_road_mapper/ros/sigint_hook.h"

namespace ipm_road_mapper {

// What one save did.
struct MapSaveResult {
  bool ok = false;
  bool diverted = false;  // written to a <stem>_reset<N> file (see MapSaveTarget)
  MapFilePaths paths;
  std::string message;  // "<n> markings, <m> lanes to <files>" or the error
};

class MapSaver {
 public:
  using LatestFn = std::function<std::shared_ptr<const MapSnapshot>()>;
  // Run in the saver thread on SIGINT (the nodelet's final save).
  using SigintFn = std::function<void()>;

  // Starts the saver thread. `period_s` 0: no periodic saves (the thread still waits for
  // SIGINT when `on_sigint` is set).
  MapSaver(std::string json_path, std::optional<GeoOrigin> geo_origin, double period_s,
           std::string node_name, LatestFn latest, SigintFn on_sigint);
  // Stop().
  ~MapSaver();

  // Stops and joins the saver thread (idempotent; a save in progress completes).
  void Stop();

  // Saves `map`, made after `generation` resets, now in the calling thread. Logs only a
  // diverted save; the caller logs the result.
  MapSaveResult Save(const VectorMap& map, std::uint64_t generation);

  // For the diagnostics.
  MapSaveStatus status() const;

 private:
  void Run();
  void Autosave();

  const std::optional<GeoOrigin> geo_origin_;
  const double period_s_;
  const std::string node_name_;
  const LatestFn latest_;
  const SigintFn on_sigint_;

  mutable std::mutex mutex_;  // every save, and the members below
  MapSaveTarget target_;
  MapSaveStatus status_;
  std::uint64_t saved_version_ = 0;  // snapshot map_version of the last autosave
  bool saved_any_ = false;
  std::uint64_t logged_diverted_ = 0;  // the last reset whose diverted save was logged
  bool logged_error_ = false;          // saver thread only: the autosave error throttle
  std::chrono::steady_clock::time_point last_error_log_;

  std::unique_ptr<SigintHook> sigint_;
  int stop_read_fd_ = -1, stop_write_fd_ = -1;  // a byte here stops the thread
  std::thread thread_;                          // last: started after everything above exists
};

}  // namespace ipm_road_mapper
