#include "ipm_road_mapper/core/mapper/window_coordinator.h"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace ipm_road_mapper {

WindowCoordinator::WindowCoordinator(const MapperOptions& options,
                                     const Eigen::Isometry3d& T_base_cam_initial, MapStore* store,
                                     MapperCounters* counters)
    : options_(options),
      T_base_cam_initial_(T_base_cam_initial),
      T_base_cam_(T_base_cam_initial),
      store_(store),
      counters_(counters),
      extrinsic_prior_(T_base_cam_initial, options.backend.rotation_prior_sigma_rad,
                       options.backend.translation_prior_sigma_m,
                       options.backend.extrinsic_prior_memory_markings) {
  extrinsic_covariance_ = extrinsic_prior_.H().inverse();
  if (options_.backend.enabled) backend_ = std::make_unique<Backend>(options_.backend);
}

WindowCoordinator::~WindowCoordinator() {
  if (backend_) backend_->Stop();
}

bool WindowCoordinator::LanesRefined() const {
  return backend_ && options_.backend.lane_residual != LaneResidual::kNone;
}

BackendStats WindowCoordinator::stats() const {
  return backend_ ? backend_->stats() : BackendStats();
}

PoseCovariance WindowCoordinator::PoseCovarianceOf(std::size_t index) const {
  const BackendOptions& o = options_.backend;
  const Eigen::Isometry3d T_map_base = store_->CorrectedPose(index);
  const PoseCovariance odometry =
      OdometryPoseCovariance(T_map_base, o.pose_prior_sigma_trans_m, o.pose_prior_sigma_rot_rad);
  if (pose_covariance_frame_ < 0 || static_cast<std::size_t>(pose_covariance_frame_) > index)
    return odometry;
  const std::size_t solved = static_cast<std::size_t>(pose_covariance_frame_);
  return PropagatePoseCovariance(pose_covariance_, store_->frames()[solved].T_map_base, T_map_base,
                                 solved == index ? PoseCovariance::Zero() : odometry);
}

void WindowCoordinator::Reset() {
  pose_covariance_frame_ = -1;
  if (!backend_) return;
  backend_->Stop();  // results of the old map must not land in the new one
  backend_ = std::make_unique<Backend>(options_.backend);
}

void WindowCoordinator::OnFrameUsed(std::uint64_t frames_used, const CameraIntrinsics& camera) {
  camera_ = camera;
  if (frames_used % options_.backend.solve_every_n_frames != 0) return;
  if (backend_) {
    backend_->Submit(BuildSnapshot());
    return;
  }
  // Without a back end the markings that leave the window retire all the same, so that the
  // front end's per-frame work stays with the live ones.
  const std::size_t first = WindowStart();
  for (MarkingElement& m : store_->markings()) {
    if (m.last_frame < first) m.retired = true;
  }
  store_->RetireMarkings(first);
}

std::size_t WindowCoordinator::WindowStart() const {
  const std::size_t window = static_cast<std::size_t>(options_.backend.window_frames);
  const std::size_t frames = store_->frames().size();
  return frames > window ? frames - window : 0;
}

bool WindowCoordinator::Finish(double time_budget_s) {
  if (!backend_ || store_->frames().empty()) return true;
  const auto start = std::chrono::steady_clock::now();
  auto remaining_s = [&] {
    return time_budget_s -
           std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  backend_->Submit(BuildSnapshot());
  if (!backend_->WaitIdleFor(remaining_s())) return false;  // its result comes later, if ever
  ApplyResults();
  FinalGlobalSolve(remaining_s());
  return remaining_s() >= 0.0;
}

double WindowCoordinator::RoadPriorSigma(const RoadSurfaceEstimate& road) const {
  const BackendOptions& o = options_.backend;
  // Beyond the own lane the crown's slope change (its prior, marginalized: the retired
  // factor has no kappa of its own) widens the sigma (road_cross_section_prior_residual.h).
  const double beyond_m = std::max(0.0, std::abs(road.lateral_m) - o.road_crown_lateral_m);
  return std::hypot(std::hypot(o.road_height_sigma_m, o.road_height_sigma_per_m * road.distance_m),
                    o.road_crown_slope_sigma * beyond_m);
}

}  // namespace ipm_road_mapper
