#include "ipm_road_mapper/ros/mapper_nodelet.h"

#include <ros/package.h>
#include <tf2/exceptions.h>
#include <time.h>

#include <boost/bind/bind.hpp>
#include <cstdio>
#include <limits>
#include <pluginlib/class_list_macros.hpp>
#include <stdexcept>
#include <utility>

#include "ipm_road_mapper/pipeline/map_files.h"
#include "ipm_road_mapper/ros/msg_conversion.h"
#include "ipm_road_mapper/ros/param_bridge.h"

namespace ipm_road_mapper {
namespace {

constexpr double kResetTimeoutS = 2.0;

// CPU time of the calling thread (ms): what one publication costs, whatever else runs.
double ThreadCpuMs() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return 1e3 * static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_nsec);
}

}  // namespace

MapperNodelet::~MapperNodelet() { Shutdown(); }

void MapperNodelet::onInit() {
  node_name_ = getName();
  LoadParameters();  // throws on a bad parameter: the manager reports the failed load
  tf_buffer_ = std::make_unique<tf2_ros::Buffer>();
  const TransformLookup lookup = [this](const std::string& parent, const std::string& child,
                                        Eigen::Isometry3d* T) -> std::string {
    try {  // ros::Time(0): the latest transform, no waiting
      return TransformToIsometry(tf_buffer_->lookupTransform(parent, child, ros::Time(0)).transform,
                                 T);
    } catch (const tf2::TransformException& e) {
      return e.what();
    }
  };
  MappingWorker::Hooks hooks;
  hooks.on_update = [this](const SessionUpdate& update, const FrameOutputs& outputs) {
    AfterUpdate(update, outputs);
  };
  hooks.on_image = [this](const sensor_msgs::ImageConstPtr& image) {
    if (debug_image_) debug_image_->AddImage(image);
  };
  hooks.overlay_wanted = [this] { return debug_image_ && debug_image_->active(); };
  // The mapping thread starts idle; inputs reach it only once SetUpInputs subscribed.
  worker_ = std::make_unique<MappingWorker>(config_, classes_, node_name_, lookup, hooks);
  if (!config_.ros.save_map_path.empty()) {
    saver_ = std::make_unique<MapSaver>(
        config_.ros.save_map_path, config_.geo_origin, config_.ros.autosave_period_s, node_name_,
        [this] { return worker_->Latest(); },
        [this] { SaveAtShutdown(std::chrono::steady_clock::now() + ShutdownBudget()); });
  }
  SetUpOutputs();
  SetUpInputs();
  NODELET_INFO("%s: waiting for masks through %s (+ %s) and %s; %s sync", node_name_.c_str(),
               mask_sub_->description().c_str(), config_.ros.camera_info_topic.c_str(),
               config_.ros.odom_topic.c_str(), config_.ros.sync.c_str());
}

void MapperNodelet::LoadParameters() {
  ros::NodeHandle& private_nh = getPrivateNodeHandle();
  try {
    config_ = LoadMapperConfig(OptionsReader(ParamsToYaml(private_nh, {}), ""));
    const std::string classes_file =
        config_.ros.classes_file.empty()
            ? FindPackageFile(ros::package::getPath("ipm_road_mapper"), "config/classes.yaml")
            : config_.ros.classes_file;
    classes_ = ClassTable::LoadFile(classes_file);
  } catch (const OptionsError& e) {
    NODELET_FATAL("invalid parameter %s: %s", private_nh.getNamespace().c_str(), e.what());
    throw;
  }
  const std::string live_error = CheckLiveConfig(config_);
  if (!live_error.empty()) {
    NODELET_FATAL("%s: refusing to map: %s", private_nh.getNamespace().c_str(), live_error.c_str());
    throw OptionsError(live_error);
  }
  NODELET_INFO_STREAM("ipm_road_mapper options:\n"
                      << ToString(config_.mapper) << ToString(config_.ros));
}

void MapperNodelet::SetUpOutputs() {
  ros::NodeHandle& nh = getNodeHandle();
  ros::NodeHandle& private_nh = getPrivateNodeHandle();
  ros::NodeHandle output_nh(private_nh);  // timers and services on our own queue
  output_nh.setCallbackQueue(&output_queue_);
  map_publisher_ = std::make_unique<MapPublisher>(private_nh, config_.ros.path_max_poses,
                                                  config_.ros.marker_full_period_s,
                                                  config_.ros.vector_map_full_period_s);
  pose_publisher_ = std::make_unique<PosePublisher>(private_nh, config_.ros.publish_map_to_odom);
  debug_image_ = std::make_unique<DebugImagePublisher>(
      nh, private_nh, config_.ros.image_topic, config_.mapper, classes_,
      [this](const sensor_msgs::ImageConstPtr& image) { OnImage(image); });
  diagnostics_ = std::make_unique<MapperDiagnostics>(nh, private_nh, node_name_,
                                                     [this] { return Snapshot(); });
  save_srv_ = output_nh.advertiseService("save_map", &MapperNodelet::OnSaveMap, this);
  reset_srv_ = output_nh.advertiseService("reset", &MapperNodelet::OnReset, this);
  // Wall timers: a paused or finished bag freezes ROS time, the outputs must still go out.
  publish_timer_ =
      output_nh.createWallTimer(ros::WallDuration(1.0 / config_.ros.publish_rate_hz),
                                [this](const ros::WallTimerEvent&) { OnPublishTimer(); });
  diagnostics_timer_ =
      output_nh.createWallTimer(ros::WallDuration(config_.ros.diagnostics_period_s),
                                [this](const ros::WallTimerEvent&) { diagnostics_->Update(); });
  output_spinner_ = std::make_unique<ros::AsyncSpinner>(1, &output_queue_);
  output_spinner_->start();
}

void MapperNodelet::SetUpInputs() {
  ros::NodeHandle& nh = getNodeHandle();
  const RosOptions& topics = config_.ros;
  const int queue = config_.ros.sync_queue_size;
  tf_listener_ = std::make_unique<tf2_ros::TransformListener>(*tf_buffer_, nh);
  try {
    mask_sub_ = std::make_unique<MaskInput>(nh, topics.mask_topic, topics.mask_transport, queue);
  } catch (const std::invalid_argument& e) {
    NODELET_FATAL("%s: %s", node_name_.c_str(), e.what());
    throw;
  }
  info_sub_.subscribe(nh, topics.camera_info_topic, queue);
  mask_sub_->registerCallback(boost::function<void(const sensor_msgs::ImageConstPtr&)>(
      [this](const sensor_msgs::ImageConstPtr& mask) {
        diagnostics_->Count(MapperInput::kMask);
        std::lock_guard<std::mutex> lock(stats_mutex_);
        mask_gaps_.Add(mask->header.seq, ToSeconds(mask->header.stamp));
      }));
  info_sub_.registerCallback(boost::function<void(const sensor_msgs::CameraInfoConstPtr&)>(
      [this](const sensor_msgs::CameraInfoConstPtr&) {
        diagnostics_->Count(MapperInput::kCameraInfo);
      }));
  using boost::placeholders::_1;
  using boost::placeholders::_2;
  if (topics.sync == "approximate") {
    ApproximatePolicy policy(queue);
    policy.setMaxIntervalDuration(ros::Duration(config_.ros.approximate_sync_max_interval_s));
    approximate_sync_ = std::make_unique<message_filters::Synchronizer<ApproximatePolicy>>(
        std::as_const(policy), *mask_sub_, info_sub_);  // const: the policy constructor
    approximate_sync_->registerCallback(boost::bind(&MapperNodelet::OnFrame, this, _1, _2));
  } else {
    exact_sync_ = std::make_unique<message_filters::Synchronizer<ExactPolicy>>(
        ExactPolicy(queue), *mask_sub_, info_sub_);
    exact_sync_->registerCallback(boost::bind(&MapperNodelet::OnFrame, this, _1, _2));
  }
  odom_sub_ = nh.subscribe(topics.odom_topic, config_.ros.odom_queue_size,
                           &MapperNodelet::OnOdometry, this);
}

void MapperNodelet::OnFrame(const sensor_msgs::ImageConstPtr& mask_msg,
                            const sensor_msgs::CameraInfoConstPtr& info_msg) {
  const auto start = std::chrono::steady_clock::now();
  diagnostics_->Count(MapperInput::kPair);
  if (shutting_down_) return;
  FrameItem frame;
  frame.stamp = ToSeconds(mask_msg->header.stamp);
  frame.camera_frame = mask_msg->header.frame_id;
  const std::string mask_error = ImageToMask(*mask_msg, &frame.mask);
  const std::string info_error = CameraInfoToIntrinsics(*info_msg, &frame.camera);
  if (!mask_error.empty()) {
    frame.error = "bad_mask_encoding: " + mask_error;
  } else if (!info_error.empty()) {
    frame.error = "bad_camera_info: " + info_error;
  }
  worker_->Push(std::move(frame));
  RecordCallbackTime(start, true);
}

void MapperNodelet::OnOdometry(const nav_msgs::OdometryConstPtr& msg) {
  const auto start = std::chrono::steady_clock::now();
  diagnostics_->Count(MapperInput::kOdometry);
  {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    odometry_gaps_.Add(msg->header.seq, ToSeconds(msg->header.stamp));
  }
  if (shutting_down_) return;
  OdometryItem odometry;
  odometry.frame_id = msg->header.frame_id;
  const std::string error = OdometryToStampedPose(*msg, &odometry.pose);
  if (!error.empty()) {
    // Handed on as a NaN pose, so the assembler counts it as bad_odometry (as map_from_bag).
    NODELET_WARN_THROTTLE(5.0, "bad odometry: %s", error.c_str());
    odometry.pose.stamp = ToSeconds(msg->header.stamp);
    odometry.pose.T_map_base.matrix().setConstant(std::numeric_limits<double>::quiet_NaN());
  }
  worker_->Push(std::move(odometry));
  RecordCallbackTime(start, false);
}

void MapperNodelet::OnImage(const sensor_msgs::ImageConstPtr& image) {
  diagnostics_->Count(MapperInput::kImage);
  if (!shutting_down_) worker_->Push(ImageItem{image});
}

void MapperNodelet::RecordCallbackTime(std::chrono::steady_clock::time_point start, bool frame) {
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  std::lock_guard<std::mutex> lock(stats_mutex_);
  ++callbacks_;
  callback_total_ms_ += ms;
  callback_max_ms_ = std::max(callback_max_ms_, ms);
  if (frame) {
    ++frame_callbacks_;
    frame_callback_total_ms_ += ms;
    frame_callback_max_ms_ = std::max(frame_callback_max_ms_, ms);
  }
}

void MapperNodelet::AfterUpdate(const SessionUpdate& update, const FrameOutputs& outputs) {
  pose_publisher_->Publish(outputs, FromSeconds(update.used.back().stamp));
  if (debug_image_ && outputs.overlay_map) {
    debug_image_->AddFrame(update.used.back(), outputs.T_map_base, outputs.T_base_cam,
                           outputs.overlay_map);
  }
}

void MapperNodelet::OnPublishTimer() {
  if (shutting_down_) return;
  const std::shared_ptr<const MapSnapshot> snapshot = worker_->Latest();
  if (!snapshot->map) return;
  const bool changed = snapshot->map_version != published_version_;
  if (!changed && !map_publisher_->full_markers_due() && !map_publisher_->full_map_due()) return;
  published_version_ = snapshot->map_version;
  const double cpu_start_ms = ThreadCpuMs();
  const PublishCounts counts = map_publisher_->Publish(
      *snapshot->map, snapshot->map_frame, config_.mapper.input.base_frame,
      snapshot->refined_camera_frame, FromSeconds(snapshot->newest_frame_stamp), changed,
      snapshot->changes.get());
  const double cpu_ms = ThreadCpuMs() - cpu_start_ms;
  if (changed && snapshot->changes)
    worker_->Published(snapshot->resets, snapshot->changes->revision);
  std::lock_guard<std::mutex> lock(stats_mutex_);
  ++publishes_;
  publish_last_ = counts;
  publish_cpu_last_ms_ = cpu_ms;
  publish_cpu_total_ms_ += cpu_ms;
  publish_cpu_max_ms_ = std::max(publish_cpu_max_ms_, cpu_ms);
}

bool MapperNodelet::OnSaveMap(ipm_road_mapper::SaveMap::Request& request,
                              ipm_road_mapper::SaveMap::Response& response) {
  const std::shared_ptr<const MapSnapshot> snapshot = worker_->Latest();
  response.success = false;
  if (request.path.empty()) {
    response.message = "path is empty";
  } else if (!snapshot->map) {
    response.message = "no map yet: " + snapshot->status.extrinsic_status;
  } else {
    const std::shared_ptr<const VectorMap> full = snapshot->FullMap();
    const VectorMap& map = *full;
    const MapFilePaths paths = MapFilePathsFor(request.path);
    try {
      SaveMapFiles(map, config_.geo_origin, paths);
      response.success = true;
      response.message = "wrote " + std::to_string(map.markings.size()) + " markings and " +
                         std::to_string(map.lanes.size()) + " lanes to " +
                         SavedFilesText(paths, config_.geo_origin.has_value());
    } catch (const std::exception& e) {
      response.message = e.what();
    }
  }
  if (response.success) {
    NODELET_INFO("save_map: %s", response.message.c_str());
  } else {
    NODELET_WARN("save_map: %s", response.message.c_str());
  }
  return true;
}

bool MapperNodelet::OnReset(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& response) {
  response.success = worker_->Reset(kResetTimeoutS, &response.message);
  if (!response.success) {
    NODELET_WARN("reset: %s", response.message.c_str());
    return true;
  }
  map_publisher_->Clear(worker_->Latest()->map_frame, ros::Time::now());
  published_version_ = worker_->Latest()->map_version;
  NODELET_INFO("reset: %s", response.message.c_str());
  return true;
}

MapperStatusSnapshot MapperNodelet::Snapshot() {
  MapperStatusSnapshot s = worker_->Latest()->status;
  s.inputs_dropped = worker_->dropped();
  std::lock_guard<std::mutex> lock(stats_mutex_);
  s.callbacks = callbacks_;
  s.callback_mean_ms = callbacks_ ? callback_total_ms_ / callbacks_ : 0.0;
  s.callback_max_ms = callback_max_ms_;
  s.frame_callback_mean_ms = frame_callbacks_ ? frame_callback_total_ms_ / frame_callbacks_ : 0.0;
  s.frame_callback_max_ms = frame_callback_max_ms_;
  s.publishes = publishes_;
  s.publish_cpu_last_ms = publish_cpu_last_ms_;
  s.publish_cpu_mean_ms = publishes_ ? publish_cpu_total_ms_ / publishes_ : 0.0;
  s.publish_cpu_max_ms = publish_cpu_max_ms_;
  s.publish_last_markers = publish_last_.markers;
  s.publish_last_delta_elements = publish_last_.delta_elements;
  s.publish_last_bytes = publish_last_.serialized_bytes;
  s.mask_queue_size = config_.ros.sync_queue_size;
  s.odom_queue_size = config_.ros.odom_queue_size;
  s.mask_gaps = mask_gaps_.stats();
  s.odometry_gaps = odometry_gaps_.stats();
  if (saver_) s.save = saver_->status();
  return s;
}

std::chrono::steady_clock::duration MapperNodelet::ShutdownBudget() const {
  return std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(config_.ros.shutdown_budget_s));
}

void MapperNodelet::Shutdown() {
  const auto deadline = std::chrono::steady_clock::now() + ShutdownBudget();
  shutting_down_ = true;
  if (worker_) worker_->CloseInputs();  // a waiting ~reset answers at once
  // Stop everything that calls into this object; each call waits for a running callback
  // (none of them waits for the mapping thread longer than the ~reset time-out).
  publish_timer_.stop();
  diagnostics_timer_.stop();
  save_srv_.shutdown();
  reset_srv_.shutdown();
  odom_sub_.shutdown();
  if (mask_sub_) mask_sub_->Shutdown();
  info_sub_.unsubscribe();
  if (debug_image_) debug_image_->Shutdown();
  if (output_spinner_) output_spinner_->stop();  // joins the output thread
  if (saver_) saver_->Stop();  // joins the saver thread (a SIGINT save in it completes)
  if (worker_ && saver_) SaveAtShutdown(deadline);
  if (worker_) worker_->Stop();  // joins the mapping thread
  if (callbacks_ > 0) {
    NODELET_INFO(
        "%s: %lu data callbacks, %.3f ms mean, %.3f ms max; %lu publications, %.2f ms CPU "
        "mean, %.2f ms max",
        node_name_.c_str(), static_cast<unsigned long>(callbacks_), callback_total_ms_ / callbacks_,
        callback_max_ms_, static_cast<unsigned long>(publishes_),
        publishes_ ? publish_cpu_total_ms_ / publishes_ : 0.0, publish_cpu_max_ms_);
  }
  exact_sync_.reset();
  approximate_sync_.reset();
  saver_.reset();
  worker_.reset();  // the session: the Mapper's optimizer thread is stopped and joined here
  tf_listener_.reset();
  tf_buffer_.reset();
  diagnostics_.reset();
  debug_image_.reset();
  map_publisher_.reset();
  pose_publisher_.reset();
}

void MapperNodelet::SaveAtShutdown(std::chrono::steady_clock::time_point deadline) {
  std::lock_guard<std::mutex> lock(final_save_mutex_);
  if (final_save_done_) return;
  final_save_done_ = true;
  bool finished = false;
  const std::shared_ptr<const VectorMap> map = worker_->Finish(deadline, &finished);
  const std::shared_ptr<const MapSnapshot> latest = worker_->Latest();
  if (!map) {
    LogFinalSave(false, node_name_ + ": nothing to save at shutdown to " +
                            config_.ros.save_map_path + ": " + latest->status.extrinsic_status);
    return;
  }
  const MapSaveResult result = saver_->Save(*map, latest->resets);
  if (!result.ok) {
    LogFinalSave(false, node_name_ + ": cannot save the map at shutdown to " + result.paths.json +
                            ": " + result.message);
    return;
  }
  LogFinalSave(true, node_name_ + ": map saved at shutdown: " + result.message + " (" +
                         (finished ? "finished map"
                                   : "the last solve ran past ros/shutdown_budget_s: "
                                     "latest snapshot") +
                         ")");
}

void MapperNodelet::LogFinalSave(bool ok, const std::string& message) {
  if (ok) {
    NODELET_INFO("%s", message.c_str());
  } else {
    NODELET_ERROR("%s", message.c_str());
  }
  // Once ros::shutdown began (a manager or mapper_node exiting without the SIGINT save,
  // e.g. ros::shutdown() called by code), rosconsole is shut down and the line above prints
  // nothing: the result still reaches the console.
  if (ros::isShuttingDown() || !ros::ok()) {
    std::fprintf(stderr, "%s\n", message.c_str());
  }
}

}  // namespace ipm_road_mapper

PLUGINLIB_EXPORT_CLASS(ipm_road_mapper::MapperNodelet, nodelet::Nodelet)
