// The nodelet's map outputs, published from an immutable snapshot of the map (never under
// the Mapper's lock): ~vector_map_delta (what changed since the previous delta, at the
// publish rate), ~vector_map (latched; the whole map every `vector_map_full_period_s`),
// ~markers (latched; only the markers of new or changed elements and lane chunks and
// DELETEs of vanished ones, the full set to a new subscriber and every
// `marker_full_period_s`), ~corrected_path (the newest poses), and the refined extrinsic
// as the static transform base_frame -> refined camera frame (sent again only when it
// changed). Between full messages, a publication's size follows what changed, not the
// map's length.
#pragma once

#include <ros/node_handle.h>
#include <ros/publisher.h>
#include <tf2_ros/static_transform_broadcaster.h>

#include <atomic>
#include <cstddef>
#include <mutex>
#include <optional>
#include <string>

#include "ipm_road_mapper/core/map/shared_vector_map.h"
#include "ipm_road_mapper/core/map/vector_map.h"
#include "ipm_road_mapper/core/mapper/map_changes.h"
#include "ipm_road_mapper/ros/marker_builder.h"
#include "ipm_road_mapper/ros/vector_map_delta_builder.h"

namespace ipm_road_mapper {

// What one Publish sent (for the diagnostics and the publish-cost measurement).
struct PublishCounts {
  std::size_t markers = 0;           // ~markers entries (ADD and DELETE)
  std::size_t delta_elements = 0;    // ~vector_map_delta markings + lanes + removed ids
  std::size_t full_elements = 0;     // ~vector_map markings + lanes (0 when not sent)
  std::size_t path_poses = 0;        // ~corrected_path poses (0 when not sent)
  std::size_t serialized_bytes = 0;  // of every message above
};

class MapPublisher {
 public:
  // Advertises on `private_nh`. `path_max_poses`: ~corrected_path keeps the newest N poses;
  // the full marker set goes out at least every `marker_full_period_s`, the full
  // ~vector_map every `vector_map_full_period_s`.
  MapPublisher(ros::NodeHandle& private_nh, int path_max_poses, double marker_full_period_s,
               double vector_map_full_period_s);

  // Publishes one map snapshot in `map_frame` at `stamp`, and the refined extrinsic as
  // base_frame -> refined_camera_frame. `map_changed` false: only a due full marker set or
  // full ~vector_map (the map was published before). Thread-safe (one publication at a
  // time).
  // `changes` (optional): the core's changes of `map` since the revision of the last map
  // published or an older one (MapChanges): the delta and the changed markers are then
  // built from them, at a cost that follows what changed; the full sets still from `map`
  // (copied out of its shared storage only then).
  PublishCounts Publish(const SharedVectorMap& map, const std::string& map_frame,
                        const std::string& base_frame, const std::string& refined_camera_frame,
                        const ros::Time& stamp, bool map_changed = true,
                        const MapChanges* changes = nullptr);

  // What the `changes` given to Publish must carry: each changed lane's tail with the
  // context its builders' chunks need (the whole lane is not needed; the mapping thread
  // exports these, MappingWorker).
  static ChangesOptions ChangesNeeded();

  // True when the next Publish sends the full marker set (a new ~markers subscriber, or
  // the period elapsed).
  bool full_markers_due() const;

  // True when the next Publish sends the full ~vector_map: the map changed since the last
  // one and `vector_map_full_period_s` elapsed (so the final map always goes out in full).
  bool full_map_due() const;

  // After ~reset: an empty map, an empty path, every marker deleted.
  void Clear(const std::string& map_frame, const ros::Time& stamp);

 private:
  bool FullMapDueLocked(const ros::WallTime& now) const;

  mutable std::mutex mutex_;
  int path_max_poses_;
  ros::WallDuration marker_full_period_;
  ros::WallDuration vector_map_full_period_;
  ros::WallTime last_full_markers_, last_full_map_;
  std::atomic<bool> new_marker_subscriber_{true};
  bool full_map_stale_ = false;  // the map changed since the last full ~vector_map
  ros::Publisher vector_map_pub_, delta_pub_, markers_pub_, path_pub_;
  tf2_ros::StaticTransformBroadcaster static_tf_;
  MarkerBuilder markers_;
  VectorMapDeltaBuilder deltas_;
  std::optional<Eigen::Isometry3d> last_T_base_cam_;
};

}  // namespace ipm_road_mapper
