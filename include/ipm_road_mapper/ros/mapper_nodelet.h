// The mapper as a nodelet (ipm_road_mapper/MapperNodelet; mapper_node wraps it). Wiring
// only: parameters -> MapperConfig, subscriptions -> MappingSession (under one mutex),
// a wall timer -> MapPublisher / diagnostics, services ~save_map and ~reset. Every topic,
// parameter, service and frame is listed in docs/ros_api.md.
//
// Threading: data callbacks (masks + camera_info, odometry, the debug image) run on the
// nodelet's single-threaded queue; the publish and diagnostics timers and the services on
// `output_queue_`, a queue this object owns, served by its own spinner thread. `mutex_`
// guards the session (Mapper + FrameAssembler, neither is thread-safe) and the state next
// to it; ExportMap is the only map copy made under it, and nothing is published while it
// is held. The Mapper's optimizer is its own thread: no callback waits for it (only the
// shutdown save does, in Mapper::Finish).
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

#include <chrono>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>

#include "ipm_road_mapper/SaveMap.h"
#include "ipm_road_mapper/ros/debug_image_publisher.h"
#include "ipm_road_mapper/ros/map_publisher.h"
#include "ipm_road_mapper/pipeline/mapper_config.h"
#include "ipm_road_mapper/ros/mapper_diagnostics.h"
#include "ipm_road_mapper/pipeline/mapping_session.h"

namespace ipm_road_mapper {

class MapperNodelet : public nodelet::Nodelet {
 public:
  MapperNodelet() = default;
  // Stops every input, timer and service, saves the map when ros/save_map_path is set, then
  // destroys the Mapper (its optimizer thread is joined).
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

  void OnFrame(const sensor_msgs::ImageConstPtr& mask, const sensor_msgs::CameraInfoConstPtr& info);
  void OnOdometry(const nav_msgs::OdometryConstPtr& msg);
  // Under mutex_: starts the session once the extrinsic is known (non-blocking tf lookup).
  bool EnsureStartedLocked(const std::string& camera_frame);
  // What a data callback takes out of the lock after a session call.
  struct UpdateOutputs {
    Eigen::Isometry3d T_map_base = Eigen::Isometry3d::Identity();  // newest used frame
    Eigen::Isometry3d T_base_cam = Eigen::Isometry3d::Identity();
    std::string map_frame, base_frame;
    std::shared_ptr<const VectorMap> overlay_map;  // set when a debug overlay is due
  };
  // Under mutex_: notes a change and copies the newest used frame's pose and the extrinsic.
  UpdateOutputs CollectLocked(const SessionUpdate& update);
  // Outside mutex_: skip warnings, ~corrected_odom and the debug overlay of a used frame.
  void AfterUpdate(const SessionUpdate& update, const UpdateOutputs& outputs);
  // Wall time of one data callback; `used_frames`: frames it ran through the Mapper.
  void RecordCallbackTime(std::chrono::steady_clock::time_point start, std::size_t used_frames);

  void OnPublishTimer();
  bool OnSaveMap(ipm_road_mapper::SaveMap::Request& request,
                 ipm_road_mapper::SaveMap::Response& response);
  bool OnReset(std_srvs::Trigger::Request& request, std_srvs::Trigger::Response& response);
  // The map as it is now, with the nodelet's metadata; empty optional before start.
  std::optional<VectorMap> ExportLocked() const;
  MapperStatusSnapshot Snapshot();
  void Shutdown();

  MapperConfig config_;
  ClassTable classes_;
  std::string node_name_;

  mutable std::mutex mutex_;  // guards everything down to the ROS handles
  std::unique_ptr<MappingSession> session_;
  std::string camera_frame_, refined_frame_, map_frame_, extrinsic_status_;
  std::uint64_t changes_ = 0, published_changes_ = 0;
  double last_frame_stamp_ = 0.0;
  std::uint64_t callbacks_ = 0, frame_callbacks_ = 0;
  double callback_total_ms_ = 0.0, callback_max_ms_ = 0.0;
  double frame_callback_total_ms_ = 0.0, frame_callback_max_ms_ = 0.0;
  bool shutting_down_ = false;
  std::chrono::steady_clock::time_point last_overlay_;

  // Declared before every handle that uses it, so it is destroyed after them.
  ros::CallbackQueue output_queue_;
  std::unique_ptr<ros::AsyncSpinner> output_spinner_;
  std::unique_ptr<tf2_ros::Buffer> tf_buffer_;
  std::unique_ptr<tf2_ros::TransformListener> tf_listener_;
  // Subscribers before the synchronizers: the synchronizers disconnect from them when
  // destroyed, so they must go first (members are destroyed in reverse order).
  message_filters::Subscriber<sensor_msgs::Image> mask_sub_;
  message_filters::Subscriber<sensor_msgs::CameraInfo> info_sub_;
  std::unique_ptr<message_filters::Synchronizer<ExactPolicy>> exact_sync_;
  std::unique_ptr<message_filters::Synchronizer<ApproximatePolicy>> approximate_sync_;
  ros::Subscriber odom_sub_;
  ros::Publisher corrected_odom_pub_;
  ros::WallTimer publish_timer_, diagnostics_timer_;
  ros::ServiceServer save_srv_, reset_srv_;
  std::unique_ptr<MapPublisher> map_publisher_;
  std::unique_ptr<DebugImagePublisher> debug_image_;
  std::unique_ptr<MapperDiagnostics> diagnostics_;
};

}  // namespace ipm_road_mapper
