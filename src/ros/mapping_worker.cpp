#include "ipm_road_mapper/ros/mapping_worker.h"

#include <ros/console.h>

#include <algorithm>
#include <utility>

#include "ipm_road_mapper/core/frontend/class_size_check.h"
#include "ipm_road_mapper/core/mapper/lane_topology.h"
#include "ipm_road_mapper/ros/map_publisher.h"

namespace ipm_road_mapper {
namespace {

using Seconds = std::chrono::duration<double>;

MappingWorker::Clock::duration Period(double rate_hz) {
  return std::chrono::duration_cast<MappingWorker::Clock::duration>(Seconds(1.0 / rate_hz));
}

// Poses per frozen trajectory chunk.
constexpr std::size_t kTrajectoryChunkPoses = 1000;
// Frames a solve may still change: a window and its context frames are far fewer.
constexpr std::size_t kMutableFramesPerWindowFrame = 10;

}  // namespace

std::shared_ptr<const VectorMap> MapSnapshot::FullMap() const {
  if (!map) return nullptr;
  auto full = std::make_shared<VectorMap>(map->ToVectorMap());
  full->trajectory = FullTrajectory(trajectory_prefix, map->header.trajectory);
  LinkLaneTopology(&full->lanes);  // a live snapshot's map has none (ExportOptions)
  return full;
}

MappingWorker::MappingWorker(const MapperConfig& config, const ClassTable& classes,
                             std::string node_name, TransformLookup lookup, Hooks hooks)
    : config_(config),
      node_name_(std::move(node_name)),
      lookup_(std::move(lookup)),
      hooks_(std::move(hooks)),
      export_period_(Period(config.ros.publish_rate_hz)),
      overlay_period_(Period(config.ros.debug_image_rate_hz)),
      session_(config.mapper, classes, config.ros.odometry_wait_s),
      frozen_trajectory_(kTrajectoryChunkPoses),
      queue_(static_cast<std::size_t>(config.ros.input_queue_size)),
      latest_(std::make_shared<const MapSnapshot>()) {
  next_export_ = Clock::now();
  thread_ = std::thread([this] { Run(); });
}

MappingWorker::~MappingWorker() { Stop(); }

void MappingWorker::Push(MapperInputItem item) {
  const std::optional<MapperInputItem> dropped = queue_.Push(std::move(item));
  if (!dropped) return;
  const InputKind kind = KindOf(*dropped);
  ++dropped_[static_cast<std::size_t>(kind)];
  ROS_WARN_THROTTLE(5.0,
                    "%s: the mapping thread falls behind: input queue full (%zu), oldest %s "
                    "dropped (counted on /diagnostics)",
                    node_name_.c_str(), queue_.capacity(), InputKindName(kind));
}

std::shared_ptr<const MapSnapshot> MappingWorker::Latest() const {
  std::lock_guard<std::mutex> lock(snapshot_mutex_);
  return latest_;
}

std::array<std::uint64_t, kInputKindCount> MappingWorker::dropped() const {
  std::array<std::uint64_t, kInputKindCount> out{};
  for (std::size_t i = 0; i < kInputKindCount; ++i) out[i] = dropped_[i].load();
  return out;
}

bool MappingWorker::Reset(double timeout_s, std::string* message) {
  std::unique_lock<std::mutex> lock(command_mutex_);
  const std::uint64_t target = resets_done_ + 1;
  reset_requested_ = true;
  queue_.Wake();
  const bool done = command_done_.wait_for(lock, Seconds(timeout_s), [&] {
    return resets_done_ >= target || stop_ || inputs_closed_ || finish_requested_;
  });
  if (done && resets_done_ >= target) {
    *message = "map, waiting frames and odometry cleared";
    return true;
  }
  if (reset_requested_ && !reset_running_) {
    reset_requested_ = false;  // not begun: cancelled, the map stays as it is
    *message = done ? "not reset: the nodelet is shutting down"
                    : "not reset: the mapping thread did not take the command within " +
                          std::to_string(timeout_s) + " s";
  } else {
    *message = "the reset is still running after " + std::to_string(timeout_s) + " s";
  }
  return false;
}

void MappingWorker::CloseInputs() {
  queue_.Close();
  {
    std::lock_guard<std::mutex> lock(command_mutex_);
    inputs_closed_ = true;
  }
  command_done_.notify_all();
}

std::shared_ptr<const VectorMap> MappingWorker::Finish(Clock::time_point deadline, bool* finished) {
  queue_.Close();  // no more inputs; what is queued is still mapped
  std::unique_lock<std::mutex> lock(command_mutex_);
  finish_requested_ = true;
  finish_deadline_ = deadline;
  queue_.Wake();
  // Past the deadline the thread is inside one frame or the final solve's export; it hands
  // over what it has within kFinishGrace (RunFinish), so the map saved is the map of every
  // frame it used, not an older periodic snapshot.
  command_done_.wait_until(lock, deadline + kFinishGrace, [this] { return finish_done_; });
  *finished = finish_done_ && !finish_past_budget_;
  if (*finished) return finished_map_;
  lock.unlock();
  return Latest()->FullMap();
}

void MappingWorker::Stop() {
  {
    std::lock_guard<std::mutex> lock(command_mutex_);
    stop_ = true;
  }
  queue_.Close();
  queue_.Wake();
  command_done_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void MappingWorker::Run() {
  while (!RunCommands()) {
    MapperInputItem item;
    if (queue_.PopUntil(next_export_, &item)) Handle(item);
    if (Clock::now() >= next_export_) {
      if (status_dirty_ || map_version_ != exported_version_) Export();
      next_export_ = Clock::now() + export_period_;
    }
  }
}

bool MappingWorker::RunCommands() {
  bool reset = false, finish = false;
  Clock::time_point deadline;
  {
    std::lock_guard<std::mutex> lock(command_mutex_);
    if (stop_) return true;
    if (finish_done_) return true;
    reset = reset_requested_;
    if (reset) reset_running_ = true;
    reset_requested_ = false;
    finish = finish_requested_;
    deadline = finish_deadline_;
  }
  if (reset) {
    session_.Reset();
    frozen_trajectory_.Clear();
    snapshot_cache_.Clear();
    ++map_version_;
    ++generation_;
    Export();  // the services and timers see the empty map at once
    {
      std::lock_guard<std::mutex> lock(command_mutex_);
      reset_running_ = false;
      ++resets_done_;
    }
    command_done_.notify_all();
    ROS_INFO("%s: reset: map, waiting frames and odometry cleared", node_name_.c_str());
  }
  if (!finish) return false;
  RunFinish(deadline);
  return true;
}

void MappingWorker::RunFinish(Clock::time_point deadline) {
  MapperInputItem item;
  while (Clock::now() < deadline && queue_.PopUntil(Clock::now(), &item)) Handle(item);
  Export();  // Latest() holds every frame handled, whatever happens next
  std::shared_ptr<const VectorMap> map;
  const bool past_budget = session_.started() && Clock::now() >= deadline;
  if (past_budget) {
    // The queue took the whole budget: no final solve; Finish saves Latest(), the map of
    // every frame used (what was still queued is dropped with the inputs).
    ROS_WARN(
        "%s: the queued frames took the whole shutdown budget: the map is saved "
        "without the final solve",
        node_name_.c_str());
  } else if (session_.started()) {
    const double budget_s = std::max(0.0, Seconds(deadline - Clock::now()).count());
    SessionUpdate update;
    session_.Finish(&update, budget_s);  // waiting frames decided, the last window solved
    ++map_version_;
    Export();
    // Exported whole, not from the frozen chunks: the final solve may move older poses.
    map = ExportFinishedMap();
  }
  {
    std::lock_guard<std::mutex> lock(command_mutex_);
    finished_map_ = std::move(map);
    finish_past_budget_ = past_budget;
    finish_done_ = true;
  }
  command_done_.notify_all();
}

void MappingWorker::Handle(MapperInputItem& item) {
  status_dirty_ = true;
  if (auto* frame = std::get_if<FrameItem>(&item)) {
    HandleFrame(*frame);
  } else if (auto* odometry = std::get_if<OdometryItem>(&item)) {
    HandleOdometry(*odometry);
  } else if (auto* image = std::get_if<ImageItem>(&item)) {
    if (hooks_.on_image) hooks_.on_image(image->image);
  }
}

void MappingWorker::HandleFrame(FrameItem& frame) {
  SessionUpdate update;
  if (!frame.error.empty()) {
    session_.CountSkipped(frame.error, &update);
  } else if (!EnsureStarted(frame.camera_frame)) {
    session_.CountSkipped("no_extrinsic: " + extrinsic_status_, &update);
  } else {
    session_.AddFrame(frame.stamp, std::move(frame.mask), frame.camera, &update);
  }
  AfterUpdate(update);
}

void MappingWorker::HandleOdometry(const OdometryItem& odometry) {
  if (!odom_frame_checked_ && !odometry.frame_id.empty()) {
    odom_frame_checked_ = true;
    if (odometry.frame_id != config_.ros.odom_frame) {
      ROS_WARN(
          "%s: the odometry is in %s, not ros/odom_frame %s: the map -> odom transform "
          "is broadcast to %s (set ros/odom_frame to the odometry's frame)",
          node_name_.c_str(), odometry.frame_id.c_str(), config_.ros.odom_frame.c_str(),
          config_.ros.odom_frame.c_str());
    }
  }
  SessionUpdate update;
  session_.AddOdometry(odometry.pose, &update);
  AfterUpdate(update);
}

bool MappingWorker::EnsureStarted(const std::string& camera_frame) {
  if (session_.started()) return true;
  ExtrinsicChoice choice;
  const std::string error =
      ChooseExtrinsic(config_.mapper.input, camera_frame, lookup_, "tf", &choice);
  if (!error.empty()) {
    extrinsic_status_ = error;
    ROS_WARN_THROTTLE(5.0, "%s: %s (frames are skipped until it is known)", node_name_.c_str(),
                      error.c_str());
    return false;
  }
  camera_frame_ = camera_frame.empty() ? std::string("camera") : camera_frame;
  refined_frame_ = config_.ros.refined_camera_frame.empty() ? camera_frame_ + "_refined"
                                                            : config_.ros.refined_camera_frame;
  if (refined_frame_ == camera_frame_) {
    ROS_ERROR(
        "%s: ros/refined_camera_frame is the camera frame %s: publishing it would give that "
        "frame a second parent; using %s_refined instead",
        node_name_.c_str(), camera_frame_.c_str(), camera_frame_.c_str());
    refined_frame_ = camera_frame_ + "_refined";
  }
  session_.Start(choice.T_base_cam);
  extrinsic_status_ = choice.source;
  ++map_version_;
  ROS_INFO("%s: rough extrinsic from %s; refined extrinsic published as %s -> %s",
           node_name_.c_str(), choice.source.c_str(), config_.mapper.input.base_frame.c_str(),
           refined_frame_.c_str());
  return true;
}

void MappingWorker::AfterUpdate(const SessionUpdate& update) {
  for (const std::string& reason : update.skipped) {
    ROS_WARN_THROTTLE(5.0, "%s: frame skipped: %s", node_name_.c_str(), reason.c_str());
  }
  if (update.used.empty()) return;
  ++map_version_;
  newest_frame_stamp_ = update.used.back().stamp;
  const Mapper& mapper = *session_.mapper();
  FrameOutputs outputs;
  const std::optional<PoseEstimate> newest = mapper.NewestPose();
  outputs.T_map_base = newest->T_map_base;
  outputs.T_map_base_covariance = newest->covariance;
  outputs.T_map_odom = newest->T_map_odom;
  outputs.T_base_cam = mapper.T_base_cam();
  outputs.map_frame = config_.ros.map_frame;
  outputs.odom_frame = config_.ros.odom_frame;
  outputs.base_frame = config_.mapper.input.base_frame;
  // The overlay draws the map as of its frame: a fresh snapshot, throttled, only when watched.
  const Clock::time_point now = Clock::now();
  if (hooks_.overlay_wanted && hooks_.overlay_wanted() && now - last_overlay_ >= overlay_period_) {
    last_overlay_ = now;
    Export();
    outputs.overlay_map = std::make_shared<const VectorMap>(exported_map_->ToVectorMap());
  }
  if (hooks_.on_update) hooks_.on_update(update, outputs);
}

std::shared_ptr<const SharedVectorMap> MappingWorker::ExportSnapshotMap() {
  const Mapper& mapper = *session_.mapper();
  const std::vector<FrameRecord>& frames = mapper.map().frames;
  const std::size_t mutable_frames =
      std::max(static_cast<std::size_t>(config_.ros.path_max_poses),
               kMutableFramesPerWindowFrame *
                   static_cast<std::size_t>(config_.mapper.backend.window_frames));
  if (frames.size() > mutable_frames) {
    frozen_trajectory_.Extend(frames, frames.size() - mutable_frames);
  }
  exported_prefix_ = frozen_trajectory_.chunks();
  // No lane topology: no message carries it; FullMap links it on its copy for a save.
  auto map = std::make_shared<SharedVectorMap>(
      mapper.ExportSnapshot(frames.size() - frozen_trajectory_.size(), &snapshot_cache_));
  Label(&map->header);
  return map;
}

std::shared_ptr<const VectorMap> MappingWorker::ExportFinishedMap() const {
  auto map = std::make_shared<VectorMap>(session_.mapper()->ExportMap());  // saved as it is
  Label(map.get());
  return map;
}

void MappingWorker::Label(VectorMap* map) const {
  map->frame_id = config_.ros.map_frame;
  map->metadata["source"] = "ipm_road_mapper/MapperNodelet " + node_name_;
  map->metadata["extrinsic_source"] = extrinsic_status_;
}

MapperStatusSnapshot MappingWorker::Status() const {
  MapperStatusSnapshot s;
  s.started = session_.started();
  s.extrinsic_status = extrinsic_status_.empty() ? "no frame yet" : extrinsic_status_;
  s.skipped_before_start = session_.skipped_before_start();
  s.assembler = session_.assembler().counters();
  if (const Mapper* mapper = session_.mapper()) {
    s.counters = mapper->counters();
    s.backend_enabled = mapper->options().backend.enabled;
    s.backend = mapper->backend_stats();
    s.T_base_cam_initial = mapper->T_base_cam_initial();
    s.T_base_cam = mapper->T_base_cam();
    s.T_base_cam_covariance = mapper->T_base_cam_covariance();
    s.extrinsic_observed = mapper->extrinsic_observed();
    for (const OversizedClass& suspect :
         MostlyOversizedClasses(s.counters.extraction, mapper->classes())) {
      s.class_table_warnings.push_back(Describe(suspect));
    }
  }
  return s;
}

void MappingWorker::Published(std::uint64_t resets, std::uint64_t revision) {
  std::lock_guard<std::mutex> lock(published_mutex_);
  published_resets_ = resets;
  published_revision_ = revision;
}

void MappingWorker::Export() {
  if (session_.started() && (map_version_ != exported_version_ || !exported_map_)) {
    exported_map_ = ExportSnapshotMap();
    std::uint64_t since = 0;  // a publisher of an older map (before a reset) gets everything
    {
      std::lock_guard<std::mutex> lock(published_mutex_);
      if (published_resets_ == generation_) since = published_revision_;
    }
    exported_changes_ = std::make_shared<const MapChanges>(
        session_.mapper()->ExportChanges(since, MapPublisher::ChangesNeeded()));
  }
  exported_version_ = map_version_;
  status_dirty_ = false;
  auto snapshot = std::make_shared<MapSnapshot>();
  snapshot->map = exported_map_;
  snapshot->changes = exported_changes_;
  snapshot->trajectory_prefix = exported_prefix_;
  snapshot->map_version = map_version_;
  snapshot->resets = generation_;
  snapshot->newest_frame_stamp = newest_frame_stamp_;
  snapshot->map_frame = config_.ros.map_frame;
  snapshot->refined_camera_frame = refined_frame_;
  snapshot->status = Status();
  std::shared_ptr<const MapSnapshot> old;
  {
    std::lock_guard<std::mutex> lock(snapshot_mutex_);
    old = std::move(latest_);
    latest_ = std::move(snapshot);
  }
  // `old` (and its map, if no reader holds it) is freed here, outside the lock.
}

}  // namespace ipm_road_mapper
