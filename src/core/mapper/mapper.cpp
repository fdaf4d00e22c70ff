#include "ipm_road_mapper/core/mapper/mapper.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include "ipm_road_mapper/core/frontend/association.h"
#include "ipm_road_mapper/core/frontend/instance_extraction.h"
#include "ipm_road_mapper/core/geometry/ipm.h"
#include "ipm_road_mapper/core/geometry/spline_fitting.h"

namespace ipm_road_mapper {

std::uint64_t MapperCounters::SkippedTotal() const {
  std::uint64_t total = 0;
  for (const auto& [reason, count] : frames_skipped) total += count;
  return total;
}

Mapper::Mapper(MapperOptions options, ClassTable classes,
               const Eigen::Isometry3d& T_base_cam_initial)
    : options_(std::move(options)),
      classes_(std::move(classes)),
      T_base_cam_initial_(T_base_cam_initial),
      T_base_cam_(T_base_cam_initial),
      extrinsic_prior_(T_base_cam_initial, options_.backend.rotation_prior_sigma_rad,
                       options_.backend.translation_prior_sigma_m) {
  // The odometry's noise, stated once (backend.pose_prior_sigma_trans_m), widens every gate.
  options_.association = EffectiveAssociationOptions(options_);
  if (options_.backend.enabled) backend_ = std::make_unique<Backend>(options_.backend);
}

Mapper::~Mapper() {
  if (backend_) backend_->Stop();
}

BackendStats Mapper::backend_stats() const { return backend_ ? backend_->stats() : BackendStats(); }

bool Mapper::LanesRefinedByBackend() const {
  return backend_ && options_.backend.lane_residual != LaneResidual::kNone;
}

void Mapper::Skip(const std::string& reason, std::string* out) {
  const std::string key = reason.substr(0, reason.find(':'));
  ++counters_.frames_skipped[key];
  if (out) *out = reason;
}

void Mapper::CountSkipped(const std::string& reason) {
  ++counters_.frames_received;
  Skip(reason, nullptr);
}

std::string Mapper::ValidateInput(const FrameInput& input) const {
  if (!std::isfinite(input.stamp)) return "bad_stamp: stamp is not finite";
  if (input.stamp <= last_stamp_) {
    std::ostringstream s;
    s << "time_jump: stamp " << input.stamp << " s is not after the last frame's " << last_stamp_
      << " s";
    return s.str();
  }
  const std::string camera_error = PinholeCamera(input.camera).Validate();
  if (!camera_error.empty()) return "bad_camera: " + camera_error;
  const std::string mask_error = ValidateMask(input.mask, input.camera.width, input.camera.height);
  if (!mask_error.empty()) return "bad_mask: " + mask_error;
  if (!IsValidTransform(input.T_map_base_odom)) {
    return "bad_pose: odometry pose is not finite or not a rotation";
  }
  return "";
}

FrameStatus Mapper::ProcessFrame(const FrameInput& input, std::string* reason) {
  ++counters_.frames_received;
  const std::string error = ValidateInput(input);
  if (!error.empty()) {
    Skip(error, reason);
    return FrameStatus::kSkipped;
  }
  last_stamp_ = input.stamp;
  camera_ = input.camera;
  ApplyBackendResults();

  using Clock = std::chrono::steady_clock;
  const auto elapsed_ms = [](Clock::time_point since) {
    return static_cast<float>(
        std::chrono::duration<double, std::milli>(Clock::now() - since).count());
  };
  const Clock::time_point start = Clock::now();
  const Ipm ipm(PinholeCamera(input.camera), T_base_cam_, options_.ipm.max_range_m);
  FrameObservations observations =
      ExtractObservations(input.mask, classes_, ipm, options_.ipm.error_model, options_.extraction);
  counters_.extraction.Add(observations.counters);
  AppendBounded(&frontend_timing_.extraction_ms, elapsed_ms(start));

  FrameRecord frame;
  frame.index = map_.frames.size();
  frame.stamp = input.stamp;
  frame.T_map_base_odom = input.T_map_base_odom;
  frame.T_map_base = input.T_map_base_odom;
  map_.frames.push_back(frame);

  OrientMarkingsAlongRoad(ipm, frame, &observations.markings);
  AddMarkings(observations, frame);
  MergeMarkings();
  AddLanes(observations, frame);
  DropSpurious(frame.index);
  AppendBounded(&frontend_timing_.total_ms, elapsed_ms(start));
  ++counters_.frames_used;
  if (backend_ && counters_.frames_used % options_.backend.solve_every_n_frames == 0) {
    backend_->Submit(BuildSnapshot());
  }
  return FrameStatus::kUsed;
}

void Mapper::DropSpurious(std::size_t frame_index) {
  const std::size_t horizon = options_.association.spurious_after_frames;
  auto spurious = [&](const auto& element) {
    return element.history.size() == 1 && frame_index > element.last_frame + horizon;
  };
  const std::size_t before = map_.markings.size() + map_.lanes.size();
  map_.markings.erase(std::remove_if(map_.markings.begin(), map_.markings.end(), spurious),
                      map_.markings.end());
  map_.lanes.erase(std::remove_if(map_.lanes.begin(), map_.lanes.end(), spurious),
                   map_.lanes.end());
  counters_.spurious_dropped += before - (map_.markings.size() + map_.lanes.size());
}

void Mapper::Reset() {
  if (backend_) {
    backend_->Stop();  // results of the old map must not land in the new one
    backend_ = std::make_unique<Backend>(options_.backend);
  }
  map_ = RoadMap();
  last_stamp_ = -1.0;
  // The extrinsic and what is known about it belong to the vehicle, not to the map: kept.
}

void Mapper::Finish() {
  if (!backend_ || map_.frames.empty()) return;
  backend_->Submit(BuildSnapshot());
  backend_->WaitIdle();
  ApplyBackendResults();
  FinalGlobalSolve();
}

VectorMap Mapper::ExportMap() const {
  VectorMap out;
  out.T_base_cam = T_base_cam_;
  out.T_base_cam_initial = T_base_cam_initial_;
  auto class_name = [this](int class_id) {
    const ClassInfo* info = classes_.Find(class_id);
    return info ? info->name : std::string("class_") + std::to_string(class_id);
  };
  // An element seen once is tentative (a spurious blob, until seen again): not exported.
  for (const MarkingElement& element : map_.markings) {
    if (element.history.size() < 2) continue;
    MapMarking marking;
    marking.id = element.id;
    marking.class_id = element.class_id;
    marking.class_name = class_name(element.class_id);
    marking.corners_map = element.corners_map;
    marking.observations = static_cast<int>(element.history.size());
    marking.first_seen = element.first_seen;
    marking.last_seen = element.last_seen;
    out.markings.push_back(marking);
  }
  for (const LaneElement& element : map_.lanes) {
    if (element.history.size() < 2) continue;
    MapLane lane;
    lane.id = element.id;
    lane.class_id = element.class_id;
    lane.class_name = class_name(element.class_id);
    const ClassInfo* info = classes_.Find(element.class_id);
    lane.style = info ? ToString(info->style) : "unknown";
    // Lanes no lane residual refines are re-fit to all their points, re-IPMed with the final
    // extrinsic and poses (PGO-IPM: lanes follow the refined extrinsic).
    lane.control_points_map =
        LanesRefinedByBackend() ? element.control_points_map : RefitControlPoints(element);
    lane.observations = static_cast<int>(element.history.size());
    lane.first_seen = element.first_seen;
    lane.last_seen = element.last_seen;
    out.lanes.push_back(std::move(lane));
  }
  for (const FrameRecord& frame : map_.frames) {
    out.trajectory.push_back({frame.stamp, frame.T_map_base});
  }
  out.metadata["method"] = options_.method;
  out.metadata["frames_received"] = counters_.frames_received;
  out.metadata["frames_used"] = counters_.frames_used;
  out.metadata["frames_skipped"] = counters_.frames_skipped;
  out.metadata["backend"] = backend_ ? ToString(options_.backend.lane_residual) : "off";
  out.metadata["backend_results_applied"] = counters_.results_applied;
  out.metadata["backend_results_rejected"] = counters_.results_rejected;
  out.metadata["frontend_time_p50_ms"] = Quantile(frontend_timing_.total_ms, 0.5);
  out.metadata["frontend_time_p95_ms"] = Quantile(frontend_timing_.total_ms, 0.95);
  out.metadata["frontend_extraction_p50_ms"] = Quantile(frontend_timing_.extraction_ms, 0.5);
  if (backend_) {
    const BackendStats stats = backend_->stats();
    out.metadata["backend_solves"] = stats.solved;
    out.metadata["backend_dropped_queue_full"] = stats.dropped_queue_full;
    out.metadata["backend_solve_time_p50_s"] = Quantile(stats.solve_times_s, 0.5);
    out.metadata["backend_solve_time_p95_s"] = Quantile(stats.solve_times_s, 0.95);
    out.metadata["backend_solve_time_max_s"] = Quantile(stats.solve_times_s, 1.0);
  }
  return out;
}

}  // namespace ipm_road_mapper
