// The nodelet's map outputs, published from an immutable snapshot of the map (never under
// the Mapper's lock): ~vector_map (latched), ~markers (latched; only the markers of new or
// changed elements and DELETEs of vanished ones, the full set to a new subscriber and
// every `marker_full_period_s`), ~corrected_path, and the refined extrinsic as the static
// transform base_frame -> refined camera frame (sent again only when it changed).
#pragma once

#include <ros/node_handle.h>
#include <ros/publisher.h>
#include <tf2_ros/static_transform_broadcaster.h>

#include <atomic>
#include <mutex>
#include <optional>
#include <string>

#include "ipm_road_mapper/core/map/vector_map.h"
#include "ipm_road_mapper/ros/marker_builder.h"

namespace ipm_road_mapper {

class MapPublisher {
 public:
  // Advertises on `private_nh`. `path_max_poses`: ~corrected_path keeps the newest N poses;
  // the full marker set goes out at least every `marker_full_period_s`.
  MapPublisher(ros::NodeHandle& private_nh, int path_max_poses, double marker_full_period_s);

  // Publishes one map snapshot in `map_frame` at `stamp`, and the refined extrinsic as
  // base_frame -> refined_camera_frame. `map_changed` false: only a due full marker set
  // (the map was published before). Thread-safe (one publication at a time).
  void Publish(const VectorMap& map, const std::string& map_frame, const std::string& base_frame,
               const std::string& refined_camera_frame, const ros::Time& stamp,
               bool map_changed = true);

  // True when the next Publish sends the full marker set (a new ~markers subscriber, or
  // the period elapsed).
  bool full_markers_due() const;

  // After ~reset: an empty map, an empty path, every marker deleted.
  void Clear(const std::string& map_frame, const ros::Time& stamp);

 private:
  mutable std::mutex mutex_;
  int path_max_poses_;
  ros::WallDuration marker_full_period_;
  ros::WallTime last_full_markers_;
  std::atomic<bool> new_marker_subscriber_{true};
  ros::Publisher vector_map_pub_, markers_pub_, path_pub_;
  tf2_ros::StaticTransformBroadcaster static_tf_;
  MarkerBuilder markers_;
  std::optional<Eigen::Isometry3d> last_T_base_cam_;
};

}  // namespace ipm_road_mapper
