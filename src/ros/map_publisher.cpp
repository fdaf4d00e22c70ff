#include "ipm_road_mapper/ros/map_publisher.h"

#include <nav_msgs/Path.h>
#include <visualization_msgs/MarkerArray.h>

#include <algorithm>

#include "ipm_road_mapper/ros/msg_conversion.h"
#include "ipm_road_mapper/ros/vector_map_conversion.h"

namespace ipm_road_mapper {

MapPublisher::MapPublisher(ros::NodeHandle& private_nh, int path_max_poses,
                           double marker_full_period_s, double vector_map_full_period_s)
    : path_max_poses_(path_max_poses),
      marker_full_period_(marker_full_period_s),
      vector_map_full_period_(vector_map_full_period_s) {
  vector_map_pub_ = private_nh.advertise<ipm_road_mapper::VectorMapMsg>("vector_map", 1, true);
  delta_pub_ = private_nh.advertise<ipm_road_mapper::VectorMapDelta>("vector_map_delta", 10);
  // A new subscriber gets the latched last message (maybe a delta), then the full set.
  const ros::SubscriberStatusCallback on_connect = [this](const ros::SingleSubscriberPublisher&) {
    new_marker_subscriber_ = true;
  };
  markers_pub_ = private_nh.advertise<visualization_msgs::MarkerArray>(
      "markers", 1, on_connect, ros::SubscriberStatusCallback(), ros::VoidConstPtr(), true);
  path_pub_ = private_nh.advertise<nav_msgs::Path>("corrected_path", 1, true);
}

ChangesOptions MapPublisher::ChangesNeeded() {
  ChangesOptions options;
  options.lane_context_points = std::max(VectorMapDeltaBuilder().lane_context_points(),
                                         MarkerBuilder().lane_context_points());
  return options;
}

PublishCounts MapPublisher::Publish(const SharedVectorMap& map, const std::string& map_frame,
                                    const std::string& base_frame,
                                    const std::string& refined_camera_frame, const ros::Time& stamp,
                                    bool map_changed, const MapChanges* changes) {
  std::lock_guard<std::mutex> lock(mutex_);
  PublishCounts counts;
  const ros::WallTime now = ros::WallTime::now();
  const bool full = new_marker_subscriber_.exchange(false) || last_full_markers_.isZero() ||
                    now - last_full_markers_ >= marker_full_period_;
  if (full) last_full_markers_ = now;
  // The whole map, copied out of the shared storage only for what needs every element.
  std::optional<VectorMap> whole;
  auto whole_map = [&]() -> const VectorMap& {
    if (!whole) whole = map.ToVectorMap();
    return *whole;
  };
  const visualization_msgs::MarkerArray markers =
      full      ? markers_.Build(whole_map(), map_frame, stamp, MarkerBuilder::Mode::kFull)
      : changes ? markers_.Build(*changes, map_frame, stamp)
                : markers_.Build(whole_map(), map_frame, stamp, MarkerBuilder::Mode::kChanges);
  if (!markers.markers.empty()) {
    markers_pub_.publish(markers);
    counts.markers = markers.markers.size();
    counts.serialized_bytes += ros::serialization::serializationLength(markers);
  }
  if (map_changed) {
    full_map_stale_ = true;
    const ipm_road_mapper::VectorMapDelta delta =
        changes ? deltas_.Build(*changes, map_frame, stamp)
                : deltas_.Build(whole_map(), map_frame, stamp);
    delta_pub_.publish(delta);
    counts.delta_elements = delta.markings.size() + delta.lanes.size() +
                            delta.removed_marking_ids.size() + delta.removed_lane_ids.size();
    counts.serialized_bytes += ros::serialization::serializationLength(delta);
    const nav_msgs::Path path = ToPathMsg(map.header.trajectory, map_frame, path_max_poses_, stamp);
    path_pub_.publish(path);
    counts.path_poses = path.poses.size();
    counts.serialized_bytes += ros::serialization::serializationLength(path);
    const Eigen::Isometry3d& T_base_cam = map.header.T_base_cam;
    const bool moved = !last_T_base_cam_ || !last_T_base_cam_->isApprox(T_base_cam, 1e-12);
    if (moved) {
      static_tf_.sendTransform(
          IsometryToTransformStamped(T_base_cam, stamp, base_frame, refined_camera_frame));
      last_T_base_cam_ = T_base_cam;
    }
  }
  if (FullMapDueLocked(now)) {
    last_full_map_ = now;
    full_map_stale_ = false;
    const ipm_road_mapper::VectorMapMsg full_map = ToVectorMapMsg(whole_map(), map_frame, stamp);
    vector_map_pub_.publish(full_map);
    counts.full_elements = full_map.markings.size() + full_map.lanes.size();
    counts.serialized_bytes += ros::serialization::serializationLength(full_map);
  }
  return counts;
}

bool MapPublisher::full_markers_due() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return new_marker_subscriber_ || last_full_markers_.isZero() ||
         ros::WallTime::now() - last_full_markers_ >= marker_full_period_;
}

bool MapPublisher::full_map_due() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return FullMapDueLocked(ros::WallTime::now());
}

bool MapPublisher::FullMapDueLocked(const ros::WallTime& now) const {
  return full_map_stale_ &&
         (last_full_map_.isZero() || now - last_full_map_ >= vector_map_full_period_);
}

void MapPublisher::Clear(const std::string& map_frame, const ros::Time& stamp) {
  std::lock_guard<std::mutex> lock(mutex_);
  VectorMap empty;
  vector_map_pub_.publish(ToVectorMapMsg(empty, map_frame, stamp));
  last_full_map_ = ros::WallTime::now();
  full_map_stale_ = false;
  delta_pub_.publish(deltas_.Clear(map_frame, stamp));
  markers_pub_.publish(markers_.Clear());
  path_pub_.publish(ToPathMsg({}, map_frame, path_max_poses_, stamp));
}

}  // namespace ipm_road_mapper
