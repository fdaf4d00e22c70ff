#include "ipm_road_mapper/ros/publish_cost_probe.h"

#include <time.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace ipm_road_mapper {
namespace {

double ThreadCpuMs() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return 1e3 * static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_nsec);
}

}  // namespace

PublishCostProbe::PublishCostProbe(const std::string& path, double publish_rate_hz,
                                   int publishes_per_km)
    : out_(path),
      path_(path),
      period_s_(publish_rate_hz > 0.0 ? 1.0 / publish_rate_hz : 0.5),
      publishes_per_km_(publishes_per_km) {
  changes_options_.lane_context_points =
      std::max(deltas_.lane_context_points(), markers_.lane_context_points());
  if (!out_) throw std::runtime_error(path + ": cannot open for writing");
  out_ << kHeader << "\n";
}

void PublishCostProbe::OnFrame(const Mapper& mapper, std::size_t frame, double stamp) {
  const std::vector<FrameRecord>& frames = mapper.map().frames;
  // New frames since the last call (a frame may have been skipped): the distance driven.
  for (; frames_seen_ < frames.size(); ++frames_seen_) {
    const Eigen::Vector3d p = frames[frames_seen_].T_map_base_odom.translation();
    if (last_position_) driven_m_ += (p - *last_position_).norm();
    last_position_ = p;
  }
  if (next_publish_stamp_ >= 0.0 && stamp < next_publish_stamp_) return;
  next_publish_stamp_ = stamp + period_s_;
  // Every publish runs the incremental builders (they follow the map as the nodelet's do);
  // only those near a whole kilometre are timed and written, with the old way beside them.
  const int km = static_cast<int>(std::floor(driven_m_ / 1000.0));
  if (km != km_) {
    km_ = km;
    measured_this_km_ = 0;
  }
  if (km >= 1 && measured_this_km_ < publishes_per_km_) {
    ++measured_this_km_;
    Measure(mapper, frame, stamp);
    return;
  }
  const MapChanges changes = mapper.ExportChanges(revision_, changes_options_);
  revision_ = changes.revision;
  const ros::Time t(stamp);
  deltas_.Build(changes, "map", t);
  markers_.Build(changes, "map", t);
  mapper.ExportSnapshot(1, &snapshots_);
}

void PublishCostProbe::Measure(const Mapper& mapper, std::size_t frame, double stamp) {
  const ros::Time t(stamp);
  double start = ThreadCpuMs();
  const MapChanges changes = mapper.ExportChanges(revision_, changes_options_);
  const double export_changes_ms = ThreadCpuMs() - start;
  revision_ = changes.revision;
  start = ThreadCpuMs();
  deltas_.Build(changes, "map", t);
  markers_.Build(changes, "map", t);
  const double publish_ms = ThreadCpuMs() - start;
  // The nodelet's snapshot export (the elements, one pose, no lane topology: what changed
  // since the last publish built, the rest shared), then the same copied whole as before,
  // and the old way's builders on that whole map (every element fingerprinted).
  start = ThreadCpuMs();
  mapper.ExportSnapshot(1, &snapshots_);
  const double export_snapshot_ms = ThreadCpuMs() - start;
  ExportOptions options;
  options.max_trajectory_poses = 1;
  options.lane_topology = false;
  start = ThreadCpuMs();
  const VectorMap snapshot = mapper.ExportMap(options);
  const double export_snapshot_old_ms = ThreadCpuMs() - start;
  start = ThreadCpuMs();
  old_deltas_.Build(snapshot, "map", t);
  old_markers_.Build(snapshot, "map", t, MarkerBuilder::Mode::kChanges);
  const double publish_old_ms = ThreadCpuMs() - start;
  char row[256];
  std::snprintf(row, sizeof(row), "%.3f,%zu,%.3f,%zu,%zu,%zu,%.4f,%.4f,%.4f,%.4f,%.4f",
                driven_m_ / 1e3, frame, stamp, snapshot.markings.size(), snapshot.lanes.size(),
                changes.map.markings.size() + changes.map.lanes.size(), export_changes_ms,
                export_snapshot_ms, publish_ms, publish_old_ms, export_snapshot_old_ms);
  out_ << row << std::endl;
}

void PublishCostProbe::Close() {
  out_.flush();
  if (!out_) throw std::runtime_error(path_ + ": write error");
  out_.close();
}

}  // namespace ipm_road_mapper
