#include "ipm_road_mapper/ros/vector_map_conversion.h"

#include <algorithm>

#include "ipm_road_mapper/core/map/lane_samples.h"
#include "ipm_road_mapper/ros/msg_conversion.h"

namespace ipm_road_mapper {
namespace {

// A stamp that ros::Time accepts (it throws on negative or out-of-range seconds).
ros::Time SafeTime(double seconds) {
  if (!(seconds >= 0.0) || seconds > 4294967295.0) return ros::Time(0);
  return FromSeconds(seconds);
}

// The lane's unmeasured flags for its control points from `from` on (the messages' per-point
// flags): empty when none is.
std::vector<std::uint8_t> UnmeasuredFlags(const MapLane& lane, std::size_t from) {
  const std::vector<bool> points = UnmeasuredPointFlags(lane);
  from = std::min(from, points.size());
  if (std::find(points.begin() + from, points.end(), true) == points.end()) return {};
  return std::vector<std::uint8_t>(points.begin() + from, points.end());
}

}  // namespace

void SetUnmeasuredFlags(const std::vector<std::uint8_t>& flags, std::size_t first_index,
                        MapLane* lane) {
  std::vector<bool> set(flags.size());
  for (std::size_t i = 0; i < flags.size(); ++i) set[i] = flags[i] != 0;
  SetUnmeasuredFrom(first_index, set, lane);
}

ipm_road_mapper::MarkingPolygon ToMarkingMsg(const MapMarking& marking) {
  ipm_road_mapper::MarkingPolygon m;
  m.id = marking.id;
  m.class_id = marking.class_id;
  m.class_name = marking.class_name;
  for (int i = 0; i < 4; ++i) m.corners[i] = ToPointMsg(marking.corners_map[i]);
  m.observations = marking.observations;
  m.first_seen = SafeTime(marking.first_seen);
  m.last_seen = SafeTime(marking.last_seen);
  for (int i = 0; i < 4; ++i) m.sides_measured[i] = marking.sides_measured[i];
  m.complete = marking.Complete();
  return m;
}

ipm_road_mapper::LaneSpline ToLaneMsg(const MapLane& lane) {
  ipm_road_mapper::LaneSpline l;
  l.id = lane.id;
  l.class_id = lane.class_id;
  l.class_name = lane.class_name;
  l.style = lane.style.empty() ? "unknown" : lane.style;
  l.control_points.reserve(lane.control_points_map.size());
  for (const Eigen::Vector3d& c : lane.control_points_map)
    l.control_points.push_back(ToPointMsg(c));
  l.unmeasured = UnmeasuredFlags(lane, 0);
  l.observations = lane.observations;
  l.first_seen = SafeTime(lane.first_seen);
  l.last_seen = SafeTime(lane.last_seen);
  l.predecessors = lane.predecessors;
  l.successors = lane.successors;
  return l;
}

ipm_road_mapper::LaneSplinePatch ToLanePatchMsg(const MapLane& lane, std::size_t from) {
  ipm_road_mapper::LaneSplinePatch patch;
  patch.id = lane.id;
  patch.class_id = lane.class_id;
  patch.class_name = lane.class_name;
  patch.style = lane.style.empty() ? "unknown" : lane.style;
  patch.first_index = static_cast<std::uint32_t>(from);
  const std::vector<Eigen::Vector3d>& cps = lane.control_points_map;
  from = std::min(from, cps.size());
  patch.control_points.reserve(cps.size() - from);
  for (std::size_t i = from; i < cps.size(); ++i)
    patch.control_points.push_back(ToPointMsg(cps[i]));
  patch.unmeasured = UnmeasuredFlags(lane, from);
  patch.observations = lane.observations;
  patch.first_seen = SafeTime(lane.first_seen);
  patch.last_seen = SafeTime(lane.last_seen);
  patch.predecessors = lane.predecessors;
  patch.successors = lane.successors;
  return patch;
}

ipm_road_mapper::VectorMapMsg ToVectorMapMsg(const VectorMap& map, const std::string& frame_id,
                                             const ros::Time& stamp) {
  ipm_road_mapper::VectorMapMsg msg;
  msg.header.frame_id = frame_id;
  msg.header.stamp = stamp;
  msg.markings.reserve(map.markings.size());
  for (const MapMarking& marking : map.markings) msg.markings.push_back(ToMarkingMsg(marking));
  msg.lanes.reserve(map.lanes.size());
  for (const MapLane& lane : map.lanes) msg.lanes.push_back(ToLaneMsg(lane));
  msg.base_to_camera = IsometryToTransform(map.T_base_cam);
  for (int i = 0; i < 36; ++i)
    msg.base_to_camera_covariance[i] = map.T_base_cam_covariance(i / 6, i % 6);
  for (int i = 0; i < 6; ++i) msg.base_to_camera_observed[i] = map.T_base_cam_observed[i];
  return msg;
}

VectorMap FromVectorMapMsg(const ipm_road_mapper::VectorMapMsg& msg) {
  VectorMap map;
  map.frame_id = msg.header.frame_id;
  for (const auto& m : msg.markings) {
    MapMarking marking;
    marking.id = m.id;
    marking.class_id = m.class_id;
    marking.class_name = m.class_name;
    for (int i = 0; i < 4; ++i) marking.corners_map[i] = FromPointMsg(m.corners[i]);
    marking.observations = m.observations;
    marking.first_seen = ToSeconds(m.first_seen);
    marking.last_seen = ToSeconds(m.last_seen);
    for (int i = 0; i < 4; ++i) marking.sides_measured[i] = m.sides_measured[i] != 0;
    map.markings.push_back(marking);
  }
  for (const auto& l : msg.lanes) {
    MapLane lane;
    lane.id = l.id;
    lane.class_id = l.class_id;
    lane.class_name = l.class_name;
    lane.style = l.style == "unknown" ? "" : l.style;
    for (const auto& c : l.control_points) lane.control_points_map.push_back(FromPointMsg(c));
    if (l.unmeasured.size() == l.control_points.size()) SetUnmeasuredFlags(l.unmeasured, 0, &lane);
    lane.observations = l.observations;
    lane.first_seen = ToSeconds(l.first_seen);
    lane.last_seen = ToSeconds(l.last_seen);
    lane.predecessors = l.predecessors;
    lane.successors = l.successors;
    map.lanes.push_back(lane);
  }
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  if (TransformToIsometry(msg.base_to_camera, &T).empty()) map.T_base_cam = T;
  map.T_base_cam_initial = map.T_base_cam;
  for (int i = 0; i < 36; ++i)
    map.T_base_cam_covariance(i / 6, i % 6) = msg.base_to_camera_covariance[i];
  for (int i = 0; i < 6; ++i) map.T_base_cam_observed[i] = msg.base_to_camera_observed[i];
  return map;
}

nav_msgs::Path ToPathMsg(const std::vector<StampedPose>& trajectory, const std::string& frame_id,
                         int max_poses, const ros::Time& fallback_stamp) {
  nav_msgs::Path path;
  path.header.frame_id = frame_id;
  path.header.stamp = trajectory.empty() ? fallback_stamp : SafeTime(trajectory.back().stamp);
  std::size_t first = 0;
  if (max_poses > 0 && trajectory.size() > static_cast<std::size_t>(max_poses)) {
    first = trajectory.size() - static_cast<std::size_t>(max_poses);
  }
  path.poses.reserve(trajectory.size() - first);
  for (std::size_t i = first; i < trajectory.size(); ++i) {
    geometry_msgs::PoseStamped pose;
    pose.header.frame_id = frame_id;
    pose.header.stamp = SafeTime(trajectory[i].stamp);
    pose.pose = IsometryToPose(trajectory[i].T_map_base);
    path.poses.push_back(pose);
  }
  return path;
}

}  // namespace ipm_road_mapper
