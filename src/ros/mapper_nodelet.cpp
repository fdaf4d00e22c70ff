#include "ipm_road_mapper/ros/mapper_nodelet.h"

#include <ros/package.h>
#include <tf2/exceptions.h>

#include <boost/bind/bind.hpp>
#include <limits>
#include <pluginlib/class_list_macros.hpp>
#include <utility>

#include "ipm_road_mapper/pipeline/extrinsic_source.h"
#include "ipm_road_mapper/pipeline/map_files.h"
#include "ipm_road_mapper/ros/msg_conversion.h"
#include "ipm_road_mapper/ros/param_bridge.h"

namespace ipm_road_mapper {
MapperNodelet::~MapperNodelet() { Shutdown(); }

void MapperNodelet::onInit() {
  node_name_ = getName();
  LoadParameters();  // throws on a bad parameter: the manager reports the failed load
  SetUpOutputs();
  SetUpInputs();
  NODELET_INFO("%s: waiting for %s (+ %s) and %s; %s sync", node_name_.c_str(),
               config_.ros.mask_topic.c_str(),
               config_.ros.camera_info_topic.c_str(),
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
  session_ =
      std::make_unique<MappingSession>(config_.mapper, classes_, config_.ros.odometry_wait_s);
  NODELET_INFO_STREAM("ipm_road_mapper options:\n"
                      << ToString(config_.mapper) << ToString(config_.ros));
}

void MapperNodelet::SetUpOutputs() {
  ros::NodeHandle& nh = getNodeHandle();
  ros::NodeHandle& private_nh = getPrivateNodeHandle();
  ros::NodeHandle output_nh(private_nh);  // timers and services on our own queue
  output_nh.setCallbackQueue(&output_queue_);
  map_publisher_ = std::make_unique<MapPublisher>(private_nh, config_.ros.path_max_poses);
  corrected_odom_pub_ = private_nh.advertise<nav_msgs::Odometry>("corrected_odom", 10);
  debug_image_ = std::make_unique<DebugImagePublisher>(
      nh, private_nh, config_.ros.image_topic, config_.mapper, classes_);
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
  const RosOptions& input = config_.ros;
  const int queue = config_.ros.sync_queue_size;
  tf_buffer_ = std::make_unique<tf2_ros::Buffer>();
  tf_listener_ = std::make_unique<tf2_ros::TransformListener>(*tf_buffer_, nh);
  mask_sub_.subscribe(nh, input.mask_topic, queue);
  info_sub_.subscribe(nh, input.camera_info_topic, queue);
  mask_sub_.registerCallback(boost::function<void(const sensor_msgs::ImageConstPtr&)>(
      [this](const sensor_msgs::ImageConstPtr&) { diagnostics_->Count(MapperInput::kMask); }));
  info_sub_.registerCallback(boost::function<void(const sensor_msgs::CameraInfoConstPtr&)>(
      [this](const sensor_msgs::CameraInfoConstPtr&) {
        diagnostics_->Count(MapperInput::kCameraInfo);
      }));
  using boost::placeholders::_1;
  using boost::placeholders::_2;
  if (input.sync == "approximate") {
    ApproximatePolicy policy(queue);
    policy.setMaxIntervalDuration(ros::Duration(config_.ros.approximate_sync_max_interval_s));
    approximate_sync_ = std::make_unique<message_filters::Synchronizer<ApproximatePolicy>>(
        std::as_const(policy), mask_sub_, info_sub_);  // const: the policy constructor
    approximate_sync_->registerCallback(boost::bind(&MapperNodelet::OnFrame, this, _1, _2));
  } else {
    exact_sync_ = std::make_unique<message_filters::Synchronizer<ExactPolicy>>(
        ExactPolicy(queue), mask_sub_, info_sub_);
    exact_sync_->registerCallback(boost::bind(&MapperNodelet::OnFrame, this, _1, _2));
  }
  odom_sub_ =
      nh.subscribe(input.odom_topic, config_.ros.odom_queue_size, &MapperNodelet::OnOdometry, this);
}

bool MapperNodelet::EnsureStartedLocked(const std::string& camera_frame) {
  if (session_->started()) return true;
  const TransformLookup lookup = [this](const std::string& parent, const std::string& child,
                                        Eigen::Isometry3d* T) -> std::string {
    try {  // ros::Time(0): the latest transform, no waiting
      return TransformToIsometry(tf_buffer_->lookupTransform(parent, child, ros::Time(0)).transform,
                                 T);
    } catch (const tf2::TransformException& e) {
      return e.what();
    }
  };
  ExtrinsicChoice choice;
  const std::string error =
      ChooseExtrinsic(config_.mapper.input, camera_frame, lookup, "tf", &choice);
  if (!error.empty()) {
    extrinsic_status_ = error;
    NODELET_WARN_THROTTLE(5.0, "%s (frames are skipped until it is known)", error.c_str());
    return false;
  }
  camera_frame_ = camera_frame.empty() ? std::string("camera") : camera_frame;
  refined_frame_ = config_.ros.refined_camera_frame.empty() ? camera_frame_ + "_refined"
                                                            : config_.ros.refined_camera_frame;
  if (refined_frame_ == camera_frame_) {
    NODELET_ERROR(
        "ros/refined_camera_frame is the camera frame %s: publishing it would give "
        "that frame a second parent; using %s_refined instead",
        camera_frame_.c_str(), camera_frame_.c_str());
    refined_frame_ = camera_frame_ + "_refined";
  }
  session_->Start(choice.T_base_cam);
  extrinsic_status_ = choice.source;
  NODELET_INFO("rough extrinsic from %s; refined extrinsic published as %s -> %s",
               choice.source.c_str(), config_.mapper.input.base_frame.c_str(),
               refined_frame_.c_str());
  return true;
}

void MapperNodelet::OnFrame(const sensor_msgs::ImageConstPtr& mask_msg,
                            const sensor_msgs::CameraInfoConstPtr& info_msg) {
  const auto start = std::chrono::steady_clock::now();
  diagnostics_->Count(MapperInput::kPair);
  cv::Mat mask;
  const std::string mask_error = ImageToMask(*mask_msg, &mask);
  CameraIntrinsics camera;
  const std::string info_error = CameraInfoToIntrinsics(*info_msg, &camera);
  SessionUpdate update;
  UpdateOutputs outputs;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (shutting_down_) return;
    if (!mask_error.empty()) {
      session_->CountSkipped("bad_mask_encoding: " + mask_error, &update);
    } else if (!info_error.empty()) {
      session_->CountSkipped("bad_camera_info: " + info_error, &update);
    } else if (!EnsureStartedLocked(mask_msg->header.frame_id)) {
      session_->CountSkipped("no_extrinsic: " + extrinsic_status_, &update);
    } else {
      session_->AddFrame(ToSeconds(mask_msg->header.stamp), std::move(mask), camera, &update);
    }
    outputs = CollectLocked(update);
  }
  AfterUpdate(update, outputs);
  RecordCallbackTime(start, update.used.size());
}

void MapperNodelet::OnOdometry(const nav_msgs::OdometryConstPtr& msg) {
  const auto start = std::chrono::steady_clock::now();
  diagnostics_->Count(MapperInput::kOdometry);
  StampedPose pose;
  const std::string error = OdometryToStampedPose(*msg, &pose);
  if (!error.empty()) {
    // Handed on as a NaN pose, so the assembler counts it as bad_odometry (as map_from_bag).
    NODELET_WARN_THROTTLE(5.0, "bad odometry: %s", error.c_str());
    pose.stamp = ToSeconds(msg->header.stamp);
    pose.T_map_base.matrix().setConstant(std::numeric_limits<double>::quiet_NaN());
  }
  SessionUpdate update;
  UpdateOutputs outputs;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (shutting_down_) return;
    if (map_frame_.empty()) {
      map_frame_ = !config_.ros.map_frame.empty()  ? config_.ros.map_frame
                   : !msg->header.frame_id.empty() ? msg->header.frame_id
                                                   : std::string("map");
    }
    session_->AddOdometry(pose, &update);
    outputs = CollectLocked(update);
  }
  AfterUpdate(update, outputs);
  RecordCallbackTime(start, update.used.size());
}

MapperNodelet::UpdateOutputs MapperNodelet::CollectLocked(const SessionUpdate& update) {
  UpdateOutputs outputs;
  if (!update.used.empty()) {
    const Mapper& mapper = *session_->mapper();
    outputs.T_map_base = mapper.map().frames.back().T_map_base;
    outputs.T_base_cam = mapper.T_base_cam();
    last_frame_stamp_ = update.used.back().stamp;
    ++changes_;
    // The overlay draws the map as of its frame: one export, throttled, only when watched.
    const auto now = std::chrono::steady_clock::now();
    if (debug_image_ && debug_image_->active() &&
        std::chrono::duration<double>(now - last_overlay_).count() >=
            1.0 / config_.ros.debug_image_rate_hz) {
      last_overlay_ = now;
      if (std::optional<VectorMap> map = ExportLocked()) {
        outputs.overlay_map = std::make_shared<const VectorMap>(std::move(*map));
      }
    }
  }
  outputs.map_frame = map_frame_.empty() ? "map" : map_frame_;
  outputs.base_frame = config_.mapper.input.base_frame;
  return outputs;
}

void MapperNodelet::AfterUpdate(const SessionUpdate& update, const UpdateOutputs& outputs) {
  for (const std::string& reason : update.skipped) {
    NODELET_WARN_THROTTLE(5.0, "frame skipped: %s", reason.c_str());
  }
  if (update.used.empty()) return;
  nav_msgs::Odometry odom;
  odom.header.stamp = FromSeconds(update.used.back().stamp);
  odom.header.frame_id = outputs.map_frame;
  odom.child_frame_id = outputs.base_frame;
  odom.pose.pose = IsometryToPose(outputs.T_map_base);
  corrected_odom_pub_.publish(odom);
  if (debug_image_ && outputs.overlay_map) {
    debug_image_->AddFrame(update.used.back(), outputs.T_map_base, outputs.T_base_cam,
                           outputs.overlay_map);
  }
}

void MapperNodelet::RecordCallbackTime(std::chrono::steady_clock::time_point start,
                                       std::size_t used_frames) {
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  std::lock_guard<std::mutex> lock(mutex_);
  ++callbacks_;
  callback_total_ms_ += ms;
  callback_max_ms_ = std::max(callback_max_ms_, ms);
  if (used_frames > 0) {
    ++frame_callbacks_;
    frame_callback_total_ms_ += ms;
    frame_callback_max_ms_ = std::max(frame_callback_max_ms_, ms);
  }
}

std::optional<VectorMap> MapperNodelet::ExportLocked() const {
  if (!session_ || !session_->started()) return std::nullopt;
  VectorMap map = session_->mapper()->ExportMap();
  map.frame_id = map_frame_.empty() ? "map" : map_frame_;
  map.metadata["source"] = "ipm_road_mapper/MapperNodelet " + node_name_;
  map.metadata["extrinsic_source"] = extrinsic_status_;
  return map;
}

void MapperNodelet::OnPublishTimer() {
  std::shared_ptr<const VectorMap> map;
  std::string base_frame, refined_frame;
  ros::Time stamp;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (shutting_down_ || changes_ == published_changes_) return;
    std::optional<VectorMap> exported = ExportLocked();
    if (!exported) return;
    map = std::make_shared<const VectorMap>(std::move(*exported));
    published_changes_ = changes_;
    base_frame = config_.mapper.input.base_frame;
    refined_frame = refined_frame_;
    stamp = FromSeconds(last_frame_stamp_);
  }
  map_publisher_->Publish(*map, map->frame_id, base_frame, refined_frame, stamp);
}

bool MapperNodelet::OnSaveMap(ipm_road_mapper::SaveMap::Request& request,
                              ipm_road_mapper::SaveMap::Response& response) {
  std::optional<VectorMap> map;
  std::string status;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    map = ExportLocked();
    status = extrinsic_status_;
  }
  response.success = false;
  if (request.path.empty()) {
    response.message = "path is empty";
  } else if (!map) {
    response.message =
        "no map yet: " + (status.empty() ? std::string("no frame received") : status);
  } else {
    const MapFilePaths paths = MapFilePathsFor(request.path);
    try {
      SaveMapFiles(*map, config_.geo_origin, paths);
      response.success = true;
      response.message = "wrote " + std::to_string(map->markings.size()) + " markings and " +
                         std::to_string(map->lanes.size()) + " lanes to " + paths.json + ", " +
                         paths.geojson + ", " + paths.tum;
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
  std::string map_frame;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    session_->Reset();
    ++changes_;
    map_frame = map_frame_.empty() ? "map" : map_frame_;
  }
  map_publisher_->Clear(map_frame, ros::Time::now());
  response.success = true;
  response.message = "map, waiting frames and odometry cleared";
  NODELET_INFO("reset: %s", response.message.c_str());
  return true;
}

MapperStatusSnapshot MapperNodelet::Snapshot() {
  std::lock_guard<std::mutex> lock(mutex_);
  MapperStatusSnapshot s;
  if (!session_) return s;
  s.started = session_->started();
  s.extrinsic_status = extrinsic_status_.empty() ? "no frame yet" : extrinsic_status_;
  s.skipped_before_start = session_->skipped_before_start();
  s.assembler = session_->assembler().counters();
  if (const Mapper* mapper = session_->mapper()) {
    s.counters = mapper->counters();
    s.backend_enabled = mapper->options().backend.enabled;
    s.backend = mapper->backend_stats();
    s.T_base_cam_initial = mapper->T_base_cam_initial();
    s.T_base_cam = mapper->T_base_cam();
  }
  s.callbacks = callbacks_;
  s.callback_mean_ms = callbacks_ ? callback_total_ms_ / callbacks_ : 0.0;
  s.callback_max_ms = callback_max_ms_;
  s.frame_callback_mean_ms = frame_callbacks_ ? frame_callback_total_ms_ / frame_callbacks_ : 0.0;
  s.frame_callback_max_ms = frame_callback_max_ms_;
  return s;
}

void MapperNodelet::Shutdown() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    shutting_down_ = true;
  }
  // Stop everything that calls into this object; each call waits for a running callback
  // (none of them is called with mutex_ held, so a callback waiting for it can finish).
  publish_timer_.stop();
  diagnostics_timer_.stop();
  save_srv_.shutdown();
  reset_srv_.shutdown();
  odom_sub_.shutdown();
  mask_sub_.unsubscribe();
  info_sub_.unsubscribe();
  if (debug_image_) debug_image_->Shutdown();
  if (output_spinner_) output_spinner_->stop();  // joins the output thread
  std::optional<VectorMap> final_map;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (session_ && session_->started() && !config_.ros.save_map_path.empty()) {
      session_->Finish(nullptr);  // waiting frames decided, the last window solved
      final_map = ExportLocked();
    }
    if (callbacks_ > 0) {
      NODELET_INFO(
          "%s: %lu data callbacks, %.2f ms mean, %.2f ms max; %lu ran frames through "
          "the mapper, %.2f ms mean, %.2f ms max",
          node_name_.c_str(), static_cast<unsigned long>(callbacks_),
          callback_total_ms_ / callbacks_, callback_max_ms_,
          static_cast<unsigned long>(frame_callbacks_),
          frame_callbacks_ ? frame_callback_total_ms_ / frame_callbacks_ : 0.0,
          frame_callback_max_ms_);
    }
  }
  if (final_map) {
    try {
      SaveMapFiles(*final_map, config_.geo_origin, MapFilePathsFor(config_.ros.save_map_path));
      NODELET_INFO("map saved at shutdown: %s (%zu markings, %zu lanes)",
                   config_.ros.save_map_path.c_str(), final_map->markings.size(),
                   final_map->lanes.size());
    } catch (const std::exception& e) {
      NODELET_ERROR("cannot save the map at shutdown: %s", e.what());
    }
  }
  exact_sync_.reset();
  approximate_sync_.reset();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    session_.reset();  // the Mapper's optimizer thread is stopped and joined here
  }
  tf_listener_.reset();
  tf_buffer_.reset();
  diagnostics_.reset();
  debug_image_.reset();
  map_publisher_.reset();
}

}  // namespace ipm_road_mapper

PLUGINLIB_EXPORT_CLASS(ipm_road_mapper::MapperNodelet, nodelet::Nodelet)
