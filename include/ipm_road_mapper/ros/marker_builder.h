// The map as rviz markers (visualization_msgs/MarkerArray):
// - namespace "lanes": each lane spline sampled every 0.5 m as a LINE_STRIP;
// - "lane_control_points": its control points (phantom ends included) as a SPHERE_LIST;
// - "markings": each marking's 4 corners as a closed LINE_STRIP;
// - "marking_labels": its class name as TEXT_VIEW_FACING above its center.
// Colors by class (ClassColor). The builder remembers what it published: an element that
// left the map (a merged lane, a dropped spurious marking, a reset) gets a DELETE, so rviz
// never shows stale markers. Marker ids are the element ids (mod 2^31).
#pragma once

#include <ros/time.h>
#include <std_msgs/ColorRGBA.h>
#include <visualization_msgs/MarkerArray.h>

#include <set>
#include <string>
#include <utility>

#include "ipm_road_mapper/core/map/vector_map.h"

namespace ipm_road_mapper {

// A fixed, distinct color per class: lane classes named "*yellow*" are yellow, "*white*"
// white; every other class gets a color of a 12-color palette picked by its id.
std_msgs::ColorRGBA ClassColor(int class_id, const std::string& class_name);

// Builds MarkerArrays of successive maps, with DELETEs for what disappeared.
class MarkerBuilder {
 public:
  // Lane samples every `lane_sample_spacing_m` of arc length.
  explicit MarkerBuilder(double lane_sample_spacing_m = 0.5);

  // The markers of `map` in `frame_id` at `stamp`, plus a DELETE for every marker of the
  // previous call that is not in this map.
  visualization_msgs::MarkerArray Build(const VectorMap& map, const std::string& frame_id,
                                        const ros::Time& stamp);

  // One DELETEALL marker (after ~reset); forgets what was published.
  visualization_msgs::MarkerArray Clear();

 private:
  double lane_sample_spacing_m_;
  std::set<std::pair<std::string, int>> published_;  // (namespace, id) of the last Build
};

}  // namespace ipm_road_mapper
