#include "ipm_road_mapper/ros/mapper_diagnostics.h"

#include <diagnostic_msgs/DiagnosticStatus.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "ipm_road_mapper/core/backend/extrinsic_observability.h"
#include "ipm_road_mapper/core/geometry/rigid_transform.h"

namespace ipm_road_mapper {
namespace {

using diagnostic_msgs::DiagnosticStatus;
using diagnostic_updater::DiagnosticStatusWrapper;

constexpr std::array<const char*, kMapperInputCount> kInputNames = {
    "masks", "camera_info", "mask+camera_info pairs", "odometry", "images"};

std::uint64_t Total(const std::map<std::string, std::uint64_t>& m) {
  std::uint64_t n = 0;
  for (const auto& [key, count] : m) n += count;
  return n;
}

// Skip counts of the Mapper and, before it started, of the session.
std::map<std::string, std::uint64_t> AllSkipped(const MapperStatusSnapshot& s) {
  return s.started ? s.counters.frames_skipped : s.skipped_before_start;
}

}  // namespace

void FillInputStatus(const InputStats& inputs, DiagnosticStatusWrapper* s) {
  for (std::size_t i = 0; i < kMapperInputCount; ++i) {
    s->addf(std::string(kInputNames[i]) + " rate (Hz)", "%.2f", inputs.rates_hz[i]);
    s->add(std::string(kInputNames[i]) + " received", inputs.totals[i]);
  }
  const auto rate = [&](MapperInput input) { return inputs.rates_hz[static_cast<int>(input)]; };
  if (rate(MapperInput::kMask) <= 0.0) {
    s->summary(DiagnosticStatus::WARN, "no masks");
  } else if (rate(MapperInput::kPair) <= 0.0) {
    s->summary(DiagnosticStatus::WARN, "masks arrive but none pairs with a camera_info");
  } else if (rate(MapperInput::kOdometry) <= 0.0) {
    s->summary(DiagnosticStatus::WARN, "masks arrive but no odometry");
  } else {
    s->summary(DiagnosticStatus::OK, "inputs flowing");
  }
}

void FillFrameStatus(const MapperStatusSnapshot& now, const MapperStatusSnapshot& previous,
                     const InputStats& inputs, DiagnosticStatusWrapper* s) {
  const auto skipped = AllSkipped(now);
  const std::uint64_t skipped_total = Total(skipped);
  const std::uint64_t used = now.counters.frames_used;
  const std::uint64_t masks = inputs.totals[static_cast<int>(MapperInput::kMask)];
  const std::uint64_t pairs = inputs.totals[static_cast<int>(MapperInput::kPair)];
  s->add("frames used", used);
  s->add("frames skipped", skipped_total);
  for (const auto& [reason, count] : skipped) s->add("skipped: " + reason, count);
  s->add("masks dropped by the sync (no camera_info)", masks > pairs ? masks - pairs : 0);
  const std::uint64_t decided = now.assembler.frames_ready + Total(now.assembler.frames_skipped);
  s->add("frames waiting for odometry",
         now.assembler.frames_received > decided ? now.assembler.frames_received - decided : 0);
  s->add("odometry used", now.assembler.odometry_used);
  s->add("odometry bad", now.assembler.bad_odometry);
  s->add("odometry out of order", now.assembler.odometry_out_of_order);
  s->add("time jumps", now.assembler.time_jumps);
  // Bad lane input, by reason (docs/architecture.md, "Bad input").
  const ExtractionCounters& e = now.counters.extraction;
  s->add("lanes dropped: wider than a line", e.dropped_wide_lane);
  s->add("lanes dropped: doubling back", e.dropped_doubled_lane);
  s->add("lane rows crossing their instance twice", e.lane_rows_doubled);
  s->add("lane observations along a lane of another class (class flicker)",
         now.counters.lane_observations_other_class);
  s->add("marking views dropped: oversized", e.dropped_oversized);
  // The mask's sanity stage (mask_sanity.h).
  s->add("hatched-area instances left out", now.counters.sanity.area_instances);
  s->add("lane instances split into lines", now.counters.sanity.lane_instances_split);
  s->add("lane pieces dropped (too small)", now.counters.sanity.lane_pieces_dropped);
  s->add("lane classes resolved by evidence (class flicker)",
         now.counters.sanity.lane_class_resolved);
  for (const std::string& warning : now.class_table_warnings) s->add("class table", warning);
  s->addf("callback time mean (ms)", "%.3f", now.callback_mean_ms);
  s->addf("callback time max (ms)", "%.3f", now.callback_max_ms);
  s->addf("frame callback time mean (ms)", "%.3f", now.frame_callback_mean_ms);
  s->addf("frame callback time max (ms)", "%.3f", now.frame_callback_max_ms);
  s->add("inputs dropped (queue full): frames", now.inputs_dropped[0]);
  s->add("inputs dropped (queue full): odometry", now.inputs_dropped[1]);
  s->add("inputs dropped (queue full): images", now.inputs_dropped[2]);
  s->add("subscriber queue: masks", now.mask_queue_size);
  s->add("subscriber queue: odometry", now.odom_queue_size);
  s->add("masks lost before the callback (seq gaps)", now.mask_gaps.lost_by_seq);
  s->add("masks lost before the callback (stamp gaps)", now.mask_gaps.lost_by_stamp);
  s->add("odometry lost before the callback (seq gaps)", now.odometry_gaps.lost_by_seq);
  s->add("odometry lost before the callback (stamp gaps)", now.odometry_gaps.lost_by_stamp);
  s->add("input restarts (stamps went back)", now.mask_gaps.restarts);
  s->add("publishes", now.publishes);
  s->addf("publish_cpu_ms", "%.3f", now.publish_cpu_last_ms);
  s->addf("publish_cpu_ms mean", "%.3f", now.publish_cpu_mean_ms);
  s->addf("publish_cpu_ms max", "%.3f", now.publish_cpu_max_ms);
  s->add("publish last: markers", now.publish_last_markers);
  s->add("publish last: delta elements", now.publish_last_delta_elements);
  s->add("publish last: bytes", now.publish_last_bytes);
  const std::uint64_t new_used = used - std::min(used, previous.counters.frames_used);
  const std::uint64_t new_skipped =
      skipped_total - std::min(skipped_total, Total(AllSkipped(previous)));
  const auto dropped = [](const MapperStatusSnapshot& x) {
    return x.inputs_dropped[0] + x.inputs_dropped[1] + x.inputs_dropped[2];
  };
  const auto lost = [](const MapperStatusSnapshot& x) {
    return x.mask_gaps.lost() + x.odometry_gaps.lost();
  };
  if (dropped(now) > dropped(previous)) {
    s->summary(DiagnosticStatus::WARN, "inputs dropped: the mapping thread falls behind");
  } else if (lost(now) > lost(previous)) {
    s->summary(DiagnosticStatus::WARN,
               "masks or odometry lost before the callbacks (subscriber queue full?)");
  } else if (new_used == 0 && new_skipped > 0) {
    s->summary(DiagnosticStatus::WARN, "frames skipped, none used");
  } else if (!now.class_table_warnings.empty()) {
    s->summary(DiagnosticStatus::WARN,
               "most views of a marking class exceed its size bounds: is the class table the "
               "masks' own?");
  } else if (new_skipped > 0) {
    s->summary(DiagnosticStatus::OK, "mapping (some frames skipped)");
  } else {
    s->summary(DiagnosticStatus::OK, new_used > 0 ? "mapping" : "idle");
  }
}

void FillOptimizerStatus(const MapperStatusSnapshot& now, const MapperStatusSnapshot& previous,
                         DiagnosticStatusWrapper* s) {
  const BackendStats& b = now.backend;
  s->add("enabled", now.backend_enabled);
  s->add("windows submitted", b.submitted);
  s->add("windows solved", b.solved);
  s->add("windows dropped (queue full)", b.dropped_queue_full);
  s->add("windows unusable", b.unusable);
  s->add("results applied", now.counters.results_applied);
  s->add("results rejected", now.counters.results_rejected);
  s->add("extrinsic updates rejected (held-out frames)", now.counters.extrinsic_rejected);
  const std::vector<double>& t = b.solve_times_s;
  const double total = std::accumulate(t.begin(), t.end(), 0.0);
  s->addf("solve time last (ms)", "%.1f", t.empty() ? 0.0 : 1e3 * t.back());
  s->addf("solve time mean (ms)", "%.1f", t.empty() ? 0.0 : 1e3 * total / t.size());
  s->addf("solve time max (ms)", "%.1f",
          t.empty() ? 0.0 : 1e3 * *std::max_element(t.begin(), t.end()));
  if (!now.backend_enabled) {
    s->summary(DiagnosticStatus::OK, "disabled (front end only)");
  } else if (b.dropped_queue_full > previous.backend.dropped_queue_full) {
    // Windows come faster than they are solved (e.g. a bag played faster than real time):
    // the dropped windows' lanes and poses go unrefined, lanes fragment.
    s->summary(DiagnosticStatus::WARN,
               "the optimizer falls behind: " +
                   std::to_string(b.dropped_queue_full - previous.backend.dropped_queue_full) +
                   " window(s) dropped since the last update (input faster than the solves)");
  } else if (b.unusable > previous.backend.unusable) {
    s->summary(DiagnosticStatus::WARN, "a window solve was unusable");
  } else {
    s->summary(DiagnosticStatus::OK, "ok");
  }
}

void FillExtrinsicStatus(const MapperStatusSnapshot& now, DiagnosticStatusWrapper* s) {
  s->add("source", now.extrinsic_status);
  if (!now.started) {
    s->summary(DiagnosticStatus::WARN, "waiting for the rough extrinsic");
    return;
  }
  const double change_deg =
      RotationAngleBetween(now.T_base_cam_initial, now.T_base_cam) * 180.0 / M_PI;
  const double change_m =
      (now.T_base_cam.translation() - now.T_base_cam_initial.translation()).norm();
  const Eigen::Vector3d t = now.T_base_cam.translation();
  const Eigen::Vector3d rpy = RpyFromRotation(now.T_base_cam.linear()) * 180.0 / M_PI;
  s->addf("change rotation (deg)", "%.4f", change_deg);
  s->addf("change translation (m)", "%.4f", change_m);
  s->addf("refined xyz (m)", "%.4f %.4f %.4f", t.x(), t.y(), t.z());
  s->addf("refined rpy (deg)", "%.4f %.4f %.4f", rpy.x(), rpy.y(), rpy.z());
  const Eigen::Matrix<double, 6, 1> sigma =
      now.T_base_cam_covariance.diagonal().cwiseMax(0.0).cwiseSqrt();
  s->addf("sigma rpy (deg)", "%.4f %.4f %.4f", sigma(0) * 180.0 / M_PI, sigma(1) * 180.0 / M_PI,
          sigma(2) * 180.0 / M_PI);
  s->addf("sigma xyz (m)", "%.4f %.4f %.4f", sigma(3), sigma(4), sigma(5));
  s->add("observed", ObservedAxesText(now.extrinsic_observed));
  s->add("updates rejected (held-out frames)", now.counters.extrinsic_rejected);
  s->summary(DiagnosticStatus::OK, "known");
}

void FillSaveStatus(const MapSaveStatus& save, double wall_now, DiagnosticStatusWrapper* s) {
  if (save.path.empty()) {
    s->summary(DiagnosticStatus::OK, "off (ros/save_map_path not set)");
    return;
  }
  s->add("path", save.path);
  s->addf("autosave period (s)", "%.1f", save.autosave_period_s);
  s->add("saves", save.saves);
  s->add("failures", save.failures);
  if (save.last_wall_time <= 0.0) {
    s->add("last save wall time", "none yet");
    s->summary(DiagnosticStatus::OK, "no save yet");
    return;
  }
  s->addf("last save wall time", "%.3f", save.last_wall_time);
  s->addf("last save age (s)", "%.1f", std::max(0.0, wall_now - save.last_wall_time));
  s->add("last save status", save.last_status);
  if (save.last_ok) {
    s->summary(DiagnosticStatus::OK, "ok");
  } else {
    s->summary(DiagnosticStatus::ERROR, "last save failed: " + save.last_status);
  }
}

MapperDiagnostics::MapperDiagnostics(ros::NodeHandle& nh, ros::NodeHandle& private_nh,
                                     const std::string& name,
                                     std::function<MapperStatusSnapshot()> snapshot)
    : snapshot_fn_(std::move(snapshot)),
      updater_(nh, private_nh, name),
      last_update_(std::chrono::steady_clock::now()) {
  updater_.setHardwareID("ipm_road_mapper");
  auto task = [this](auto fill) {
    return [this, fill](DiagnosticStatusWrapper& s) {
      std::lock_guard<std::mutex> lock(mutex_);
      fill(s);
    };
  };
  updater_.add("inputs",
               task([this](DiagnosticStatusWrapper& s) { FillInputStatus(inputs_, &s); }));
  updater_.add("frames", task([this](DiagnosticStatusWrapper& s) {
                 FillFrameStatus(now_, previous_, inputs_, &s);
               }));
  updater_.add("optimizer", task([this](DiagnosticStatusWrapper& s) {
                 FillOptimizerStatus(now_, previous_, &s);
               }));
  updater_.add("extrinsic",
               task([this](DiagnosticStatusWrapper& s) { FillExtrinsicStatus(now_, &s); }));
  updater_.add("saves", task([this](DiagnosticStatusWrapper& s) {
                 const double wall_now = std::chrono::duration<double>(
                                             std::chrono::system_clock::now().time_since_epoch())
                                             .count();
                 FillSaveStatus(now_.save, wall_now, &s);
               }));
}

void MapperDiagnostics::Update() {
  MapperStatusSnapshot snapshot = snapshot_fn_();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto wall = std::chrono::steady_clock::now();
    const double dt = std::chrono::duration<double>(wall - last_update_).count();
    for (std::size_t i = 0; i < kMapperInputCount; ++i) {
      const std::uint64_t total = counts_[i].load();
      inputs_.rates_hz[i] = dt > 0 ? (total - inputs_.totals[i]) / dt : 0.0;
      inputs_.totals[i] = total;
    }
    last_update_ = wall;
    previous_ = std::move(now_);
    now_ = std::move(snapshot);
  }
  updater_.force_update();
}

}  // namespace ipm_road_mapper
