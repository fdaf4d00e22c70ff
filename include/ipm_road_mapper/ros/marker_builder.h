// The map as rviz markers (visualization_msgs/MarkerArray):
// - namespace "lanes": each lane spline sampled every 0.5 m as a LINE_STRIP;
// - "lane_control_points": its control points (phantom ends included) as a SPHERE_LIST;
// - "markings": each marking's 4 corners as a closed LINE_STRIP;
// - "marking_labels": its class name as TEXT_VIEW_FACING above its center.
// Colors by class (ClassColor). The builder remembers what it published, with a fingerprint
// of each element's class and geometry: an element that left the map (a merged lane, a
// dropped spurious marking, a reset) gets a DELETE, so rviz never shows stale markers, and
// in kChanges mode an element whose fingerprint did not change is not built nor sent again
// (the per-publish cost then follows what changed, not the map's length). Marker ids are
// the element ids (mod 2^31), stable over the element's life.
#pragma once

#include <ros/time.h>
#include <std_msgs/ColorRGBA.h>
#include <visualization_msgs/MarkerArray.h>

#include <cstddef>
#include <map>
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

  // kFull: every element's markers; kChanges: only those of elements that are new or whose
  // class or geometry changed since they were last sent.
  enum class Mode { kFull, kChanges };

  // The markers of `map` in `frame_id` at `stamp` (all of them, or the changes), plus a
  // DELETE for every marker of the previous calls that is not in this map.
  visualization_msgs::MarkerArray Build(const VectorMap& map, const std::string& frame_id,
                                        const ros::Time& stamp, Mode mode = Mode::kFull);

  // One DELETEALL marker (after ~reset); forgets what was published.
  visualization_msgs::MarkerArray Clear();

 private:
  using MarkerKey = std::pair<std::string, int>;  // (namespace, id)
  double lane_sample_spacing_m_;
  // Every marker on screen now, with the fingerprint of the element it draws.
  std::map<MarkerKey, std::size_t> published_;
};

}  // namespace ipm_road_mapper
