// The exported map (core VectorMap) <-> the package's messages (msg/VectorMap.msg), and the
// corrected trajectory -> nav_msgs/Path. Pure functions, unit-tested (test_vector_map_conversion).
#pragma once

#include <nav_msgs/Path.h>
#include <ros/time.h>

#include <cstdint>
#include <string>
#include <vector>

#include "ipm_road_mapper/LaneSplinePatch.h"
#include "ipm_road_mapper/core/geometry/rigid_transform.h"
#include "ipm_road_mapper/core/map/vector_map.h"
#include "ipm_road_mapper/ros/vector_map_msg.h"

namespace ipm_road_mapper {

// One marking / lane as its message (element stamps in seconds -> ros::Time).
ipm_road_mapper::MarkingPolygon ToMarkingMsg(const MapMarking& marking);
ipm_road_mapper::LaneSpline ToLaneMsg(const MapLane& lane);
// `lane` as a ~vector_map_delta patch carrying control_points_map[from..] (first_index
// `from`; a caller holding a lane's tail sets the index in the whole lane): ToLaneMsg's
// fields, only the points from `from` converted.
ipm_road_mapper::LaneSplinePatch ToLanePatchMsg(const MapLane& lane, std::size_t from);

// Per-point unmeasured flags (LaneSpline / LaneSplinePatch `unmeasured`, the first at
// control point `first_index`) as `lane`'s ranges from there on (SetUnmeasuredFrom): the
// ranges before first_index stay, those after are replaced.
void SetUnmeasuredFlags(const std::vector<std::uint8_t>& flags, std::size_t first_index,
                        MapLane* lane);

// VectorMap -> message in `frame_id` at `stamp`: markings (4 corners), lanes (control points,
// phantom ends included), the refined extrinsic. Element stamps in seconds -> ros::Time.
ipm_road_mapper::VectorMapMsg ToVectorMapMsg(const VectorMap& map, const std::string& frame_id,
                                             const ros::Time& stamp);

// Message -> VectorMap (frame_id from the header; trajectory and metadata empty; the
// initial extrinsic is not carried and is set to the refined one).
VectorMap FromVectorMapMsg(const ipm_road_mapper::VectorMapMsg& msg);

// The newest `max_poses` poses of a trajectory (all when max_poses <= 0) as a Path in
// `frame_id`; the path's stamp is that of its newest pose (or `fallback_stamp` if empty).
nav_msgs::Path ToPathMsg(const std::vector<StampedPose>& trajectory, const std::string& frame_id,
                         int max_poses, const ros::Time& fallback_stamp);

}  // namespace ipm_road_mapper
