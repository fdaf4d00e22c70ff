#include "ipm_road_mapper/ros/bag_input.h"

#include <rosbag/view.h>
#include <tf2/buffer_core.h>
#include <tf2/exceptions.h>
#include <tf2_msgs/TFMessage.h>

#include "ipm_road_mapper/ros/msg_conversion.h"

namespace ipm_road_mapper {
namespace {

constexpr const char* kTfStaticTopic = "/tf_static";

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

}  // namespace ipm_road_mapper
