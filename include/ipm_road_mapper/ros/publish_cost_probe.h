// The map publication's cost per publish, measured in process along a drive (map_from_bag
// --publish-stats-out, the long benchmark): at the nodelet's publish rate (in bag time) it
// builds ~vector_map_delta and the changed ~markers as MapPublisher does, from the core's
// incremental export (Mapper::ExportChanges, changed lanes as tails), and, for comparison, the old
// way from the whole exported map (fingerprints of every element), and the nodelet's snapshot
// export (Mapper::ExportSnapshot, through a SnapshotCache kept along the drive as the nodelet's
// mapping thread keeps it) beside the snapshot export before it (ExportMap without the lane
// topology, every element copied). Thread CPU of each step goes to a CSV row
// (flushed: a run stopped early keeps its rows). ExportMap with the topology (what the
// snapshot cost before: 0.66 s at 10 km) is left out: timing it would distort the run's
// own CPU per frame. Only the first
// `publishes_per_km` publishes after each whole kilometre are measured, so that the probe adds
// little to the run it measures.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <fstream>
#include <optional>
#include <string>

#include "ipm_road_mapper/core/mapper/mapper.h"
#include "ipm_road_mapper/ros/marker_builder.h"
#include "ipm_road_mapper/ros/vector_map_delta_builder.h"

namespace ipm_road_mapper {

class PublishCostProbe {
 public:
  // The CSV columns, in order.
  static constexpr const char* kHeader =
      "km,frame,stamp,markings,lanes,changed_elements,export_changes_ms,export_snapshot_ms,"
      "publish_ms,publish_old_ms,export_snapshot_old_ms";

  // Writes to `path` (throws std::runtime_error when it cannot be opened); publishes every
  // 1 / `publish_rate_hz` s of bag time (> 0).
  PublishCostProbe(const std::string& path, double publish_rate_hz, int publishes_per_km = 20);

  // After each used frame: measures a publish when one is due near a whole kilometre.
  void OnFrame(const Mapper& mapper, std::size_t frame, double stamp);

  // Flushes; throws std::runtime_error on a write error.
  void Close();

 private:
  void Measure(const Mapper& mapper, std::size_t frame, double stamp);

  std::ofstream out_;
  std::string path_;
  double period_s_;
  int publishes_per_km_;
  double next_publish_stamp_ = -1.0;
  double driven_m_ = 0.0;
  std::optional<Eigen::Vector3d> last_position_;
  std::size_t frames_seen_ = 0;
  int measured_this_km_ = 0;
  int km_ = -1;  // the whole kilometre being measured
  std::uint64_t revision_ = 0;
  VectorMapDeltaBuilder deltas_, old_deltas_;
  MarkerBuilder markers_, old_markers_;
  SnapshotCache snapshots_;         // as the nodelet's mapping thread keeps it
  ChangesOptions changes_options_;  // lane tails, as the nodelet's publisher asks for them
};

}  // namespace ipm_road_mapper
