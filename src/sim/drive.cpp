#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>

#include "ipm_road_mapper/core/geometry/rigid_transform.h"
#include "ipm_road_mapper/sim/drive_simulator.h"
#include "ipm_road_mapper/sim/sim_random.h"

namespace ipm_road_mapper {
namespace sim {
namespace {

constexpr std::int64_t kNsPerS = 1000000000LL;
constexpr double kOdometryMarginS = 0.1;  // odometry starts/ends this long around the frames

// Where the lane lines are painted: from behind the start to past what the camera sees.
double LineStart(const ScenarioOptions& o) { return std::min(0.0, o.vehicle.start_s_m - 10.0); }
double LineEnd(const ScenarioOptions& o, double road_length) {
  return std::max(road_length, o.vehicle.end_s_m + o.camera.image_range_m + 10.0);
}

}  // namespace

DriveSimulator::DriveSimulator(const ScenarioOptions& scenario, const ClassTable& classes,
                               std::uint32_t seed, int max_frames)
    : scenario_(scenario),
      seed_(seed),
      world_(scenario, classes, LineStart(scenario),
             LineEnd(scenario, RoadModel(scenario.road).length())),
      camera_(scenario.camera.intrinsics),
      T_base_cam_true_(MountToTransform(scenario.camera.mount)),
      T_base_cam_rough_(RoughExtrinsic(scenario.camera.mount, scenario.rough_extrinsic)),
      trajectory_(world_.road(), scenario.vehicle, seed),
      mask_projector_(camera_, scenario.camera.near_m, scenario.segmentation.range_m),
      image_projector_(camera_, scenario.camera.near_m, scenario.camera.image_range_m) {
  const VehicleOptions& v = scenario_.vehicle;
  const double duration = (v.end_s_m - v.start_s_m) / v.speed_mps;
  int n = static_cast<int>(std::floor(duration * scenario_.camera.rate_hz + 1e-9)) + 1;
  if (max_frames > 0) n = std::min(n, max_frames);
  for (int k = 0; k < n; ++k) frame_stamps_ns_.push_back(FrameStampNs(k));
  ComputeOdometry();
  for (const auto& [id, info] : classes.classes()) {
    if (info.kind == ElementKind::kMarking) marking_class_ids_.push_back(id);
  }
  visible_frames_.assign(world_.markings().size(), 0);
  // Lane ground truth: from the camera's first position to the range past its last one.
  lane_s0_ = trajectory_.S(0.0) + scenario_.camera.mount.x_m;
  lane_s1_ = trajectory_.S((frame_stamps_ns_.back() - frame_stamps_ns_.front()) * 1e-9) +
             scenario_.camera.mount.x_m + scenario_.segmentation.range_m;
  // A fixed sensor-texture tile for the gray image (repeats, so it compresses).
  SimRandom random = SimRandom::ForStream(seed_, RandomStream::kImage);
  texture_tile_.create(64, 64, CV_16SC1);
  for (int r = 0; r < 64; ++r) {
    for (int c = 0; c < 64; ++c) texture_tile_.at<short>(r, c) = random.UniformInt(-3, 3);
  }
}

std::int64_t DriveSimulator::FrameStampNs(int k) const {
  const std::int64_t start = std::llround(scenario_.start_time_s * 1e9);
  return start + std::llround(k * 1e9 / scenario_.camera.rate_hz);
}

bool DriveSimulator::ImageDue(int k) const {
  const int every = scenario_.camera.image_every_n_frames;
  return every > 0 && k % every == 0;
}

void DriveSimulator::ComputeOdometry() {
  const OdometryOptions& o = scenario_.odometry;
  const std::int64_t t0 = frame_stamps_ns_.front();
  const std::int64_t first =
      t0 - std::llround(kOdometryMarginS * 1e9) + std::llround(o.time_offset_s * 1e9);
  const std::int64_t last = frame_stamps_ns_.back() + std::llround(kOdometryMarginS * 1e9);
  const double dt = 1.0 / o.rate_hz;
  OdometryErrorModel error_model(o, seed_);
  for (std::int64_t j = 0;; ++j) {
    OdometrySample sample;
    sample.stamp_ns = first + std::llround(j * 1e9 / o.rate_hz);
    if (sample.stamp_ns > last + std::llround(dt * 1e9)) break;
    sample.stamp = sample.stamp_ns * 1e-9;
    const Eigen::Isometry3d T_true = trajectory_.Pose((sample.stamp_ns - t0) * 1e-9);
    sample.T_map_base = OdometryErrorModel::Apply(T_true, error_model.Next(dt));
    odometry_.push_back(sample);
  }
  // Body-frame velocities of the published (noisy) track by central differences.
  for (std::size_t j = 0; j < odometry_.size(); ++j) {
    const std::size_t a = j == 0 ? 0 : j - 1, b = std::min(j + 1, odometry_.size() - 1);
    const double span = (odometry_[b].stamp_ns - odometry_[a].stamp_ns) * 1e-9;
    const Eigen::Isometry3d& Ta = odometry_[a].T_map_base;
    const Eigen::Isometry3d& Tb = odometry_[b].T_map_base;
    const Eigen::Matrix3d R = odometry_[j].T_map_base.linear();
    odometry_[j].linear_velocity_base =
        R.transpose() * (Tb.translation() - Ta.translation()) / span;
    odometry_[j].angular_velocity_base = LogSo3(Ta.linear().transpose() * Tb.linear()) / span;
  }
  // Frame poses: the truth, and the odometry interpolated on SE(3) at the frame stamp (what
  // a mapper buffering /odom gets).
  std::size_t j = 0;
  for (std::size_t k = 0; k < frame_stamps_ns_.size(); ++k) {
    GroundTruthFrame frame;
    frame.stamp = frame_stamps_ns_[k] * 1e-9;
    frame.T_map_base_true = trajectory_.Pose((frame_stamps_ns_[k] - t0) * 1e-9);
    while (j + 2 < odometry_.size() && odometry_[j + 1].stamp_ns <= frame_stamps_ns_[k]) ++j;
    const double alpha = static_cast<double>(frame_stamps_ns_[k] - odometry_[j].stamp_ns) /
                         static_cast<double>(odometry_[j + 1].stamp_ns - odometry_[j].stamp_ns);
    frame.T_map_base_odom =
        InterpolateSe3(odometry_[j].T_map_base, odometry_[j + 1].T_map_base, alpha);
    frames_.push_back(frame);
  }
}

DriveSimulator::FrameContext DriveSimulator::MakeContext(int k) const {
  FrameContext context;
  context.index = k;
  const Eigen::Isometry3d T_map_cam = frames_[k].T_map_base_true * T_base_cam_true_;
  context.T_cam_map = T_map_cam.inverse();
  const double t = (frame_stamps_ns_[k] - frame_stamps_ns_.front()) * 1e-9;
  const double s_hint = trajectory_.S(t) + scenario_.camera.mount.x_m;
  context.s_cam = world_.road().Locate(T_map_cam.translation().head<2>(), s_hint).x();
  context.sight =
      SightProfile(world_.road(), T_map_cam.translation(), s_hint,
                   std::max(scenario_.segmentation.range_m, scenario_.camera.image_range_m) + 5.0);
  return context;
}

bool DriveSimulator::ToPixels(const SurfacePolygon& polygon, const FrameContext& context,
                              const FrustumProjector& projector, std::vector<Eigen::Vector2d>* uv) {
  std::vector<Eigen::Vector3d> polygon_cam;
  polygon_cam.reserve(polygon.vertices.size());
  for (const SurfaceVertex& v : polygon.vertices) {
    if (!context.sight.Visible(v.s, v.l, v.p_map.z())) return false;
    polygon_cam.push_back(context.T_cam_map * v.p_map);
  }
  *uv = projector.Project(polygon_cam);
  return !uv->empty();
}

SimFrame DriveSimulator::RenderFrame(int k, const RenderSettings& settings) {
  SimFrame frame;
  frame.index = k;
  frame.stamp_ns = frame_stamps_ns_[k];
  frame.stamp = frames_[k].stamp;
  frame.T_map_base_true = frames_[k].T_map_base_true;
  frame.T_map_base_odom = frames_[k].T_map_base_odom;
  const FrameContext context = MakeContext(k);
  RenderMask(context, settings.segmentation_noise, &frame);
  if (settings.image) RenderImage(context, &frame);
  if (settings.record_visibility) {
    // Once per marking and frame, however many instances (split parts) show it.
    std::vector<int> seen;
    for (const RenderedInstance& instance : frame.instances) {
      if (instance.source == RenderedInstance::Source::kMarking) seen.push_back(instance.gt_id);
    }
    std::sort(seen.begin(), seen.end());
    seen.erase(std::unique(seen.begin(), seen.end()), seen.end());
    for (int gt_id : seen) ++visible_frames_[gt_id - 1];
  }
  return frame;
}

GroundTruth DriveSimulator::ground_truth() const {
  GroundTruth gt;
  gt.scenario = scenario_.name;
  gt.seed = seed_;
  gt.frame_rate_hz = scenario_.camera.rate_hz;
  gt.camera = scenario_.camera.intrinsics;
  gt.T_base_cam_true = T_base_cam_true_;
  gt.T_base_cam_rough = T_base_cam_rough_;
  for (const SimMarking& m : world_.markings()) {
    GroundTruthMarking g;
    g.id = m.id;
    g.class_id = m.class_id;
    g.class_name = m.class_name;
    g.corners_map = m.corners_map;
    g.center_map = m.center_map;
    g.visible_frames = visible_frames_[m.id - 1];
    gt.markings.push_back(g);
  }
  for (const SimLaneLine& line : world_.lane_lines()) {
    GroundTruthLane g;
    g.id = line.id;
    g.class_id = line.class_id;
    g.class_name = line.class_name;
    g.style = ToString(line.style);
    g.points_map = world_.LanePoints(line, lane_s0_, lane_s1_);
    gt.lanes.push_back(g);
  }
  gt.frames = frames_;
  return gt;
}

}  // namespace sim
}  // namespace ipm_road_mapper
