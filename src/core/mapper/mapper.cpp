#include "ipm_road_mapper/core/mapper/mapper.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include "ipm_road_mapper/core/frontend/frame_registration.h"
#include "ipm_road_mapper/core/frontend/instance_extraction.h"
#include "ipm_road_mapper/core/geometry/ipm.h"
#include "ipm_road_mapper/core/geometry/trajectory_road_plane.h"
#include "ipm_road_mapper/core/mapper/lane_topology.h"
#include "ipm_road_mapper/core/mapper/lane_unmeasured.h"
#include "ipm_road_mapper/core/mapper/pose_extrapolator.h"
#include "ipm_road_mapper/core/mapper/timing_series.h"

namespace ipm_road_mapper {
namespace {

// The options as the rooms use them: the odometry's noise, stated once
// (backend.pose_prior_sigma_trans_m), widens every association gate.
MapperOptions WithEffectiveGates(MapperOptions options) {
  options.association = EffectiveAssociationOptions(options);
  return options;
}

// The front end's ground for a new frame at `T_map_base_odom` (IpmOptions::ground): the road
// plane of the odometry's recent trajectory (the frames used so far, newest last, then the
// new frame's), or base_link's plane z = 0.
RoadPlane FrontEndGround(const IpmOptions& options, const std::vector<FrameRecord>& frames,
                         double stamp, const Eigen::Isometry3d& T_map_base_odom) {
  if (options.ground == IpmGround::kBaseLink) return RoadPlane();
  // The frames within both windows, and one beyond them; at most kMaxRecentFrames, so that a
  // vehicle standing still (no path to cover) costs a bounded scan per frame.
  constexpr std::size_t kMaxRecentFrames = 600;
  std::size_t first = frames.size();
  double path_m = 0.0;
  Eigen::Vector3d previous = T_map_base_odom.translation();
  while (first > 0 && frames.size() - first < kMaxRecentFrames) {
    const FrameRecord& frame = frames[first - 1];
    path_m += (previous - frame.T_map_base_odom.translation()).head<2>().norm();
    previous = frame.T_map_base_odom.translation();
    --first;
    if (path_m > options.road_plane.grade_length_m &&
        stamp - frame.stamp > options.road_plane.cross_slope_window_s) {
      break;
    }
  }
  std::vector<StampedPose> recent;
  recent.reserve(frames.size() - first + 1);
  for (std::size_t i = first; i < frames.size(); ++i) {
    recent.push_back({frames[i].stamp, frames[i].T_map_base_odom});
  }
  recent.push_back({stamp, T_map_base_odom});
  return RoadPlaneFromTrajectory(recent, options.road_plane);
}

}  // namespace

std::uint64_t MapperCounters::SkippedTotal() const {
  std::uint64_t total = 0;
  for (const auto& [reason, count] : frames_skipped) total += count;
  return total;
}

Mapper::Mapper(MapperOptions options, ClassTable classes,
               const Eigen::Isometry3d& T_base_cam_initial)
    : options_(WithEffectiveGates(std::move(options))),
      classes_(std::move(classes)),
      T_base_cam_initial_(T_base_cam_initial),
      sanity_(options_.sanity, &classes_),
      store_(options_.backend.road_plane_radius_m),
      markings_(options_, &store_, &counters_),
      lanes_(options_, &store_, &counters_),
      windows_(options_, T_base_cam_initial, &store_, &counters_) {}

void Mapper::CountSkipped(SkipReason reason) {
  ++counters_.frames_received;
  ++counters_.frames_skipped[ToString(reason)];
}

void Mapper::CountSkipped(const std::string& text) {
  // "<key>: <detail>" from another layer; a key no layer names is still counted by its name.
  const std::string key = text.substr(0, text.find(':'));
  const std::optional<SkipReason> reason = ParseSkipReason(key);
  ++counters_.frames_received;
  ++counters_.frames_skipped[reason ? ToString(*reason) : key];
}

std::optional<Mapper::Invalid> Mapper::ValidateInput(const FrameInput& input) const {
  if (!std::isfinite(input.stamp)) return Invalid{SkipReason::kBadStamp, "stamp is not finite"};
  if (input.stamp <= last_stamp_) {
    std::ostringstream s;
    s << "stamp " << input.stamp << " s is not after the last frame's " << last_stamp_ << " s";
    return Invalid{SkipReason::kTimeJump, s.str()};
  }
  const std::string camera_error = PinholeCamera(input.camera).Validate();
  if (!camera_error.empty()) return Invalid{SkipReason::kBadCamera, camera_error};
  const std::string mask_error = ValidateMask(input.mask, input.camera.width, input.camera.height);
  if (!mask_error.empty()) return Invalid{SkipReason::kBadMask, mask_error};
  if (!IsValidTransform(input.T_map_base_odom)) {
    return Invalid{SkipReason::kBadPose, "odometry pose is not finite or not a rotation"};
  }
  return std::nullopt;
}

FrameStatus Mapper::ProcessFrame(const FrameInput& input, std::string* reason) {
  const std::optional<Invalid> invalid = ValidateInput(input);
  if (invalid) {
    CountSkipped(invalid->reason);
    if (reason) *reason = SkipText(invalid->reason, invalid->detail);
    return FrameStatus::kSkipped;
  }
  ++counters_.frames_received;
  last_stamp_ = input.stamp;
  windows_.ApplyResults();

  using Clock = std::chrono::steady_clock;
  const auto elapsed_ms = [](Clock::time_point since) {
    return static_cast<float>(
        std::chrono::duration<double, std::milli>(Clock::now() - since).count());
  };
  const Clock::time_point start = Clock::now();
  // Pixels go onto the road under and ahead of the vehicle, not onto base_link's plane, which
  // pitches with the body (trajectory_road_plane.h).
  const RoadPlane ground_base =
      FrontEndGround(options_.ipm, store_.frames(), input.stamp, input.T_map_base_odom);
  const Ipm ipm(PinholeCamera(input.camera), windows_.T_base_cam(), options_.ipm.max_range_m,
                ground_base);
  // The road ahead, for the far-only markings no pose has passed (far_marking_estimate.h): the
  // trajectory's plane whatever the front end's ground.
  IpmOptions trajectory_ground = options_.ipm;
  trajectory_ground.ground = IpmGround::kTrajectory;
  const RoadPlane ahead_base =
      FrontEndGround(trajectory_ground, store_.frames(), input.stamp, input.T_map_base_odom);
  const cv::Mat mask = sanity_.Clean(input.mask, ipm, input.T_map_base_odom, &counters_.sanity);
  FrameObservations observations =
      ExtractObservations(mask, classes_, ipm, options_.ipm.error_model, options_.extraction);
  counters_.extraction.Add(observations.counters);
  AppendBounded(&frontend_timing_.extraction_ms, elapsed_ms(start));

  const FrameRecord& frame = store_.AddFrame(input.stamp, input.T_map_base_odom, ground_base);
  // The lanes' association first (the markings change no lane): where the odometry's noise
  // sets the gates, the markings are associated in the frame registered across the road by
  // it (frame_registration.h).
  LaneTracker::FrameAssociation lane_association = lanes_.Associate(observations.lanes, frame);
  std::optional<double> offset_across_m;
  if (NoiseSetsTheGates(options_.association)) {
    offset_across_m = lanes_.OffsetAcross(lane_association, frame);
  }
  const RoadPlane road_ahead_map{frame.T_map_base * ahead_base.point,
                                 frame.T_map_base.linear() * ahead_base.normal};
  markings_.Update(ipm, frame, &observations.markings, offset_across_m, &road_ahead_map);
  lanes_.Update(std::move(lane_association), frame);
  markings_.DropSpurious(frame.index);
  lanes_.DropSpurious(frame.index);
  PruneHistories();
  store_.NoteRemovals();
  AppendBounded(&frontend_timing_.total_ms, elapsed_ms(start));
  ++counters_.frames_used;
  windows_.OnFrameUsed(counters_.frames_used, input.camera);
  return FrameStatus::kUsed;
}

std::optional<PoseEstimate> Mapper::NewestPose() const {
  const std::vector<FrameRecord>& frames = store_.frames();
  if (frames.empty()) return std::nullopt;
  const FrameRecord& newest = frames.back();
  PoseEstimate estimate;
  estimate.stamp = newest.stamp;
  const std::int64_t solved = store_.corrected_frame();
  estimate.T_map_base = solved >= 0 && static_cast<std::size_t>(solved) < newest.index
                            ? ExtrapolateNewestPose(frames, static_cast<std::size_t>(solved),
                                                    store_.T_map_odom(), options_.backend)
                            : store_.CorrectedPose(newest.index);
  estimate.covariance = windows_.PoseCovarianceOf(newest.index);
  estimate.T_map_odom = estimate.T_map_base * newest.T_map_base_odom.inverse();
  return estimate;
}

void Mapper::PruneHistories() {
  // Every kPruneEveryFrames frames, so that the erasures are batched.
  constexpr std::size_t kPruneEveryFrames = 100;
  const std::size_t frames = store_.frames().size();
  const std::size_t span = static_cast<std::size_t>(options_.backend.final_global_max_frames);
  if (frames % kPruneEveryFrames != 0 || frames <= span) return;
  store_.PruneHistoriesBefore(frames - span);
}

void Mapper::Reset() {
  windows_.Reset();
  sanity_.Reset();
  store_.Clear();
  last_stamp_ = -1.0;
}

bool Mapper::Finish(double time_budget_s) {
  const bool finished = windows_.Finish(time_budget_s);
  // The camera for the joins across a gap no frame saw (those are joined here only).
  if (counters_.frames_used > 0) {
    lanes_.SetCamera(windows_.camera(), windows_.T_base_cam());
    // The far-only markings on the final poses and extrinsic.
    markings_.RefreshFarOnly(PinholeCamera(windows_.camera()), windows_.T_base_cam(),
                             /*include_retired=*/true);
    // The unmeasured sides of partially seen markings, on the road from the final poses (a
    // back-end step: plain IPM, the paper's front end alone, keeps its flat-ground extents).
    if (windows_.enabled()) {
      markings_.RemeasurePartialExtents(PinholeCamera(windows_.camera()), windows_.T_base_cam());
    }
  }
  lanes_.JoinFragments();  // fragments the drive's last frames left apart
  store_.NoteRemovals();
  return finished;
}

std::string Mapper::ClassName(int class_id) const {
  const ClassInfo* info = classes_.Find(class_id);
  return info ? info->name : std::string("class_") + std::to_string(class_id);
}

void Mapper::ExportExtrinsic(VectorMap* out) const {
  out->T_base_cam = windows_.T_base_cam();
  out->T_base_cam_initial = T_base_cam_initial_;
  out->T_base_cam_covariance = windows_.T_base_cam_covariance();
  out->T_base_cam_observed = windows_.extrinsic_observed();
}

bool Mapper::ExportMarking(const MarkingElement& element, MapMarking* marking) const {
  // A tentative marking (seen once, or not yet consistently where it should have been
  // visible: MarkingTracker::CheckConsistency) is not exported.
  if (element.Observations() < 2 || !element.confirmed) return false;
  marking->id = element.id;
  marking->class_id = element.class_id;
  marking->class_name = ClassName(element.class_id);
  marking->corners_map = element.corners_map;
  marking->observations = static_cast<int>(element.Observations());
  marking->first_seen = element.first_seen;
  marking->last_seen = element.last_seen;
  marking->sides_measured = element.side_measured;
  return true;
}

bool Mapper::ExportLane(const LaneElement& element, MapLane* lane, std::size_t from) const {
  if (!element.Exported()) return false;
  lane->id = element.id;
  lane->class_id = element.class_id;
  lane->class_name = ClassName(element.class_id);
  const ClassInfo* info = classes_.Find(element.class_id);
  lane->style = info ? ToString(info->style) : "unknown";
  // Lanes no lane residual refines are re-fit to all their points, re-IPMed with the final
  // extrinsic and poses (PGO-IPM: lanes follow the refined extrinsic).
  if (!windows_.LanesRefined()) {
    lane->control_points_map =
        lanes_.RefitControlPoints(element, windows_.camera(), windows_.T_base_cam());
    lane->control_points_map.erase(
        lane->control_points_map.begin(),
        lane->control_points_map.begin() + std::min(from, lane->control_points_map.size()));
  } else {
    const auto& cps = element.control_points_map;
    lane->control_points_map.assign(cps.begin() + std::min(from, cps.size()), cps.end());
  }
  lane->unmeasured = ExportedUnmeasured(element, std::min(from, element.control_points_map.size()),
                                        lane->control_points_map.size());
  lane->observations = static_cast<int>(element.Observations());
  lane->first_seen = element.first_seen;
  lane->last_seen = element.last_seen;
  return true;
}

VectorMap Mapper::ExportMap(const ExportOptions& export_options) const {
  VectorMap out;
  ExportHeader(export_options.max_trajectory_poses, nullptr, &out);
  for (const auto* markings : {&store_.markings(), &store_.retired_markings()}) {
    for (const MarkingElement& m : *markings) {
      MapMarking marking;
      if (ExportMarking(m, &marking)) out.markings.push_back(std::move(marking));
    }
  }
  for (const LaneElement& element : store_.lanes()) {
    MapLane lane;
    if (ExportLane(element, &lane)) out.lanes.push_back(std::move(lane));
  }
  if (export_options.lane_topology) LinkLaneTopology(&out.lanes);
  return out;
}

void Mapper::ExportHeader(std::size_t max_poses, SnapshotCache* cache, VectorMap* out) const {
  ExportExtrinsic(out);
  const std::vector<FrameRecord>& frames = store_.frames();
  const std::size_t first =
      max_poses > 0 && frames.size() > max_poses ? frames.size() - max_poses : 0;
  out->trajectory.reserve(frames.size() - first);
  for (std::size_t i = first; i < frames.size(); ++i) {
    out->trajectory.push_back({frames[i].stamp, store_.CorrectedPose(i)});
  }
  nlohmann::json& metadata = out->metadata;
  metadata["method"] = options_.method;
  metadata["frames_received"] = counters_.frames_received;
  metadata["frames_used"] = counters_.frames_used;
  metadata["frames_skipped"] = counters_.frames_skipped;
  metadata["backend"] = windows_.enabled() ? ToString(options_.backend.lane_residual) : "off";
  metadata["backend_results_applied"] = counters_.results_applied;
  metadata["backend_results_rejected"] = counters_.results_rejected;
  metadata["backend_extrinsic_rejected"] = counters_.extrinsic_rejected;
  metadata["backend_joint_extrinsic_held"] = counters_.joint_extrinsic_held;
  const std::vector<float>& total_ms = frontend_timing_.total_ms;
  const std::vector<float>& extraction_ms = frontend_timing_.extraction_ms;
  metadata["frontend_time_p50_ms"] =
      cache ? cache->frontend_p50.Update(total_ms) : Quantile(total_ms, 0.5);
  metadata["frontend_time_p95_ms"] =
      cache ? cache->frontend_p95.Update(total_ms) : Quantile(total_ms, 0.95);
  metadata["frontend_extraction_p50_ms"] =
      cache ? cache->extraction_p50.Update(extraction_ms) : Quantile(extraction_ms, 0.5);
  if (windows_.enabled()) {
    const BackendStats stats = windows_.stats();
    const std::vector<double>& solve_s = stats.solve_times_s;
    metadata["backend_solves"] = stats.solved;
    metadata["backend_dropped_queue_full"] = stats.dropped_queue_full;
    metadata["backend_solve_time_p50_s"] =
        cache ? cache->solve_p50.Update(solve_s) : Quantile(solve_s, 0.5);
    metadata["backend_solve_time_p95_s"] =
        cache ? cache->solve_p95.Update(solve_s) : Quantile(solve_s, 0.95);
    metadata["backend_solve_time_max_s"] =
        cache ? cache->solve_max.Update(solve_s) : Quantile(solve_s, 1.0);
  }
}

}  // namespace ipm_road_mapper
