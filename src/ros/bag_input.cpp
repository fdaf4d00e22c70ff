#include "ipm_road_mapper/ros/bag_input.h"

#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <tf2/buffer_core.h>
#include <tf2/exceptions.h>
#include <tf2_msgs/TFMessage.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "ipm_road_mapper/ros/msg_conversion.h"

namespace ipm_road_mapper {
namespace {

constexpr const char* kTfStaticTopic = "/tf_static";

std::string FormatSeconds(double s) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(3) << s << " s";
  return out.str();
}

}  // namespace

std::map<std::string, std::string> BagTopicTypes(const rosbag::Bag& bag) {
  std::map<std::string, std::string> types;
  rosbag::View view(bag);
  for (const rosbag::ConnectionInfo* connection : view.getConnections()) {
    types[connection->topic] = connection->datatype;
  }
  return types;
}

std::string CheckBagTopics(const rosbag::Bag& bag,
                           const std::vector<std::pair<std::string, std::string>>& required) {
  const std::map<std::string, std::string> types = BagTopicTypes(bag);
  for (const auto& [topic, type] : required) {
    const auto found = types.find(topic);
    if (found == types.end()) {
      std::string list;
      for (const auto& entry : types) list += (list.empty() ? "" : ", ") + entry.first;
      return "topic " + topic + " (" + type +
             ") is not in the bag (bag topics: " + (list.empty() ? "none" : list) + ")";
    }
    if (found->second != type) {
      return "topic " + topic + " has type " + found->second + ", expected " + type;
    }
  }
  return "";
}

std::string LookupStaticTransform(const rosbag::Bag& bag, const std::string& parent_frame,
                                  const std::string& child_frame, Eigen::Isometry3d* T) {
  tf2::BufferCore buffer;
  std::size_t transforms = 0;
  rosbag::View view(bag, rosbag::TopicQuery(kTfStaticTopic));
  for (const rosbag::MessageInstance& message : view) {
    const auto tf = message.instantiate<tf2_msgs::TFMessage>();
    if (!tf) return std::string(kTfStaticTopic) + " is not tf2_msgs/TFMessage";
    for (const geometry_msgs::TransformStamped& transform : tf->transforms) {
      // setTransform rejects (and logs) malformed transforms itself.
      if (buffer.setTransform(transform, "bag", /*is_static=*/true)) ++transforms;
    }
  }
  if (transforms == 0) return std::string("the bag has no ") + kTfStaticTopic + " transforms";
  geometry_msgs::TransformStamped T_parent_child;
  try {
    T_parent_child = buffer.lookupTransform(parent_frame, child_frame, ros::Time(0));
  } catch (const tf2::TransformException& e) {
    return std::string(kTfStaticTopic) + " has no transform " + parent_frame + " -> " +
           child_frame + " (" + e.what() + ")";
  }
  const std::string error = TransformToIsometry(T_parent_child.transform, T);
  return error.empty() ? "" : std::string(kTfStaticTopic) + ": " + error;
}

CameraInfoTable CameraInfoTable::Read(const rosbag::Bag& bag, const std::string& topic) {
  CameraInfoTable table;
  rosbag::View view(bag, rosbag::TopicQuery(topic));
  for (const rosbag::MessageInstance& message : view) {
    const auto info = message.instantiate<sensor_msgs::CameraInfo>();
    if (!info) continue;  // the type was checked before; nothing else to do with it
    Entry entry;
    entry.stamp = info->header.stamp;
    entry.error = CameraInfoToIntrinsics(*info, &entry.intrinsics);
    table.entries_.push_back(std::move(entry));
  }
  std::stable_sort(table.entries_.begin(), table.entries_.end(),
                   [](const Entry& a, const Entry& b) { return a.stamp < b.stamp; });
  std::vector<double> periods;
  for (std::size_t i = 1; i < table.entries_.size(); ++i) {
    const double dt = (table.entries_[i].stamp - table.entries_[i - 1].stamp).toSec();
    if (dt > 0.0) periods.push_back(dt);
  }
  if (!periods.empty()) {
    std::nth_element(periods.begin(), periods.begin() + periods.size() / 2, periods.end());
    table.approximate_tolerance_s_ = 0.5 * periods[periods.size() / 2];
  }
  return table;
}

std::string CameraInfoTable::Match(const ros::Time& stamp, bool exact,
                                   CameraIntrinsics* intrinsics) const {
  if (entries_.empty()) return "no_camera_info: no camera_info in the bag";
  const auto after =
      std::lower_bound(entries_.begin(), entries_.end(), stamp,
                       [](const Entry& e, const ros::Time& s) { return e.stamp < s; });
  const Entry* best = nullptr;
  double best_dt = 0.0;
  for (auto it : {after - (after != entries_.begin() ? 1 : 0), after}) {
    if (it == entries_.end()) continue;
    const double dt = std::abs((it->stamp - stamp).toSec());
    if (!best || dt < best_dt) {
      best = &*it;
      best_dt = dt;
    }
  }
  const bool matched = exact ? best->stamp == stamp : best_dt <= approximate_tolerance_s_;
  if (!matched) {
    return "no_camera_info: none " +
           (exact ? std::string("with the identical stamp")
                  : "within " + FormatSeconds(approximate_tolerance_s_)) +
           " for the mask at " + FormatSeconds(stamp.toSec()) + " (nearest " +
           FormatSeconds(best_dt) + " away)";
  }
  if (!best->error.empty()) return "bad_camera_info: " + best->error;
  *intrinsics = best->intrinsics;
  return "";
}

}  // namespace ipm_road_mapper
