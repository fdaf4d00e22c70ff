// The mapper as a nodelet (ipm_road_mapper/MapperNodelet; mapper_node wraps it). Wiring
// only: parameters -> MapperConfig, subscriptions -> MappingWorker (the mapping thread),
// a wall timer -> MapPublisher / diagnostics, services ~save_map and ~reset. Every topic,
// parameter, service and frame is listed in docs/ros_api.md.
//
// Threading (docs/ros_api.md): data callbacks (masks + camera_info, odometry, the debug
// image) run on the nodelet's single-threaded queue; they only convert the message to the
// core's types and push it into the MappingWorker's bounded queue, never waiting on the
// mapper, publishing, services or the optimizer. The MappingWorker's own thread runs the
// session and swaps in immutable snapshots; the publish and diagnostics timers and the
// services run on `output_queue_`, a queue this object owns, served by its own spinner
// thread, and read the latest snapshot. ~reset is a command the mapping thread executes
// (the service waits at most 2 s). The Mapper's optimizer is its own thread.
// Unload: inputs, timers and services stop; with ros/save_map_path the mapping thread
// finishes within ros/shutdown_budget_s and the best map available is saved; the mapping
// thread is joined. With ros/save_map_path the MapSaver's thread also saves the latest
// snapshot every ros/autosave_period_s, and on SIGINT runs that final save before roscpp
// shuts down (and its logging with it), then passes the signal on.
// Why not the nodelet's multi-threaded queue: nodelet's queues hold the nodelet through a
// weak_ptr locked per callback, so an unload during a data callback destroys the nodelet at
// the end of that callback, in a worker thread, when its other queue may already be freed;
// stopping a timer registered there then touches freed memory (a manager segfault that
// test/ros/mapper_reload.test caught). Every queue our handles point to must outlive them:
// the running single-threaded queue does, and so does our own.
#pragma once

#include <message_filters/subscriber.h>
#include <message_filters/sync_policies/approximate_time.h>
#include <message_filters/sync_policies/exact_time.h>
#include <message_filters/synchronizer.h>
#include <nav_msgs/Odometry.h>
#include <nodelet/nodelet.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <ros/spinner.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <std_srvs/Trigger.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>

#include "ipm_road_mapper/SaveMap.h"
#include "ipm_road_mapper/pipeline/mapper_config.h"
#include "ipm_road_mapper/ros/debug_image_publisher.h"
#include "ipm_road_mapper/ros/map_publisher.h"
#include "ipm_road_mapper/ros/map_saver.h"
#include "ipm_road_mapper/ros/mapper_diagnostics.h"
#include "ipm_road_mapper/ros/mapping_worker.h"
#include "ipm_road_mapper/ros/mask_input.h"
#include "ipm_road_mapper/ros/pose_publisher.h"

namespace ipm_road_mapper {

class MapperNodelet : public nodelet::Nodelet {
 public:
  MapperNodelet() = default;
  // Stops every input, timer and service, saves the map when ros/save_map_path is set
  // (within ros/shutdown_budget_s), joins the mapping thread and destroys the Mapper (its
  // optimizer thread is joined).
  ~MapperNodelet() override;

 private:
  using ExactPolicy =
      message_filters::sync_policies::ExactTime<sensor_msgs::Image, sensor_msgs::CameraInfo>;
  using ApproximatePolicy =
      message_filters::sync_policies::ApproximateTime<sensor_msgs::Image, sensor_msgs::CameraInfo>;

  void onInit() override;
  void LoadParameters();
  void SetUpInputs();
  void SetUpOutputs();

  // Data callbacks: convert, push into the worker's queue, time themselves.
  void OnFrame(const sensor_msgs::ImageConstPtr& mask, const sensor_msgs::CameraInfoConstPtr& info);
  void OnOdometry(const nav_msgs::OdometryConstPtr& msg);
  void OnImage(const sensor_msgs::ImageConstPtr& image);
  void RecordCallbackTime(std::chrono::steady_clock::time_point start, bool frame);
  // In the mapping thread, after a used frame: ~corrected_odom and the debug overlay.
  void AfterUpdate(const SessionUpdate& update, const FrameOutputs& outputs);

  void OnPublishTimer();
  bool OnSaveMap(ipm_road_mapper::SaveMap::Request& request,
                 ipm_road_mapper::SaveMap::Response& response);
  bool OnReset(std_srvs::Trigger::Request& request, std_srvs::Trigger::Response& response);
  // The latest snapshot's status plus the callback, queue and publish figures.
  MapperStatusSnapshot Snapshot();
  std::chrono::steady_clock::duration ShutdownBudget() const;
  void Shutdown();
  // With ros/save_map_path: the mapping thread finishes until `deadline`, the best map
  // available is saved, and the result logged. Once only (SIGINT or unload, whichever first).
  void SaveAtShutdown(std::chrono::steady_clock::time_point deadline);
  // Logs the final save's result (also on stderr once rosconsole is shut down).
  void LogFinalSave(bool ok, const std::string& message);

  MapperConfig config_;
  ClassTable classes_;
  std::string node_name_;

  std::atomic<bool> shutting_down_{false};
  std::mutex final_save_mutex_;  // SaveAtShutdown runs once
  bool final_save_done_ = false;
  std::mutex stats_mutex_;  // the callback and publish figures below
  std::uint64_t callbacks_ = 0, frame_callbacks_ = 0;
  double callback_total_ms_ = 0.0, callback_max_ms_ = 0.0;
  double frame_callback_total_ms_ = 0.0, frame_callback_max_ms_ = 0.0;
  std::uint64_t publishes_ = 0;
  double publish_cpu_last_ms_ = 0.0, publish_cpu_total_ms_ = 0.0, publish_cpu_max_ms_ = 0.0;
  PublishCounts publish_last_;
  InputGapCounter mask_gaps_, odometry_gaps_;  // written by the data callbacks
  std::uint64_t published_version_ = 0;        // output thread only

  // Declared before every handle that uses it, so it is destroyed after them.
  ros::CallbackQueue output_queue_;
  std::unique_ptr<ros::AsyncSpinner> output_spinner_;
  std::unique_ptr<tf2_ros::Buffer> tf_buffer_;
  std::unique_ptr<tf2_ros::TransformListener> tf_listener_;
  // Subscribers before the synchronizers: the synchronizers disconnect from them when
  // destroyed, so they must go first (members are destroyed in reverse order).
  std::unique_ptr<MaskInput> mask_sub_;  // ros/mask_transport
  message_filters::Subscriber<sensor_msgs::CameraInfo> info_sub_;
  std::unique_ptr<message_filters::Synchronizer<ExactPolicy>> exact_sync_;
  std::unique_ptr<message_filters::Synchronizer<ApproximatePolicy>> approximate_sync_;
  ros::Subscriber odom_sub_;
  std::unique_ptr<PosePublisher> pose_publisher_;  // ~corrected_odom, map -> odom
  ros::WallTimer publish_timer_, diagnostics_timer_;
  ros::ServiceServer save_srv_, reset_srv_;
  std::unique_ptr<MapPublisher> map_publisher_;
  std::unique_ptr<DebugImagePublisher> debug_image_;
  std::unique_ptr<MapperDiagnostics> diagnostics_;
  // Its thread calls into the publishers above, so it is stopped before they go.
  std::unique_ptr<MappingWorker> worker_;
  // Last: its thread reads worker_'s snapshots (and finishes it on SIGINT).
  std::unique_ptr<MapSaver> saver_;
};

}  // namespace ipm_road_mapper
