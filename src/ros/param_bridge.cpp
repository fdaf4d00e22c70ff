#include "ipm_road_mapper/ros/param_bridge.h"

#include <algorithm>

namespace ipm_road_mapper {

YAML::Node XmlRpcToYaml(const XmlRpc::XmlRpcValue& value) {
  // XmlRpcValue's accessors are non-const; they do not modify a value of the right type.
  auto& v = const_cast<XmlRpc::XmlRpcValue&>(value);
  switch (v.getType()) {
    case XmlRpc::XmlRpcValue::TypeBoolean:
      return YAML::Node(static_cast<bool>(v));
    case XmlRpc::XmlRpcValue::TypeInt:
      return YAML::Node(static_cast<int>(v));
    case XmlRpc::XmlRpcValue::TypeDouble:
      return YAML::Node(static_cast<double>(v));
    case XmlRpc::XmlRpcValue::TypeString:
      return YAML::Node(static_cast<std::string>(v));
    case XmlRpc::XmlRpcValue::TypeArray: {
      YAML::Node seq(YAML::NodeType::Sequence);
      for (int i = 0; i < v.size(); ++i) seq.push_back(XmlRpcToYaml(v[i]));
      return seq;
    }
    case XmlRpc::XmlRpcValue::TypeStruct: {
      YAML::Node map(YAML::NodeType::Map);
      for (auto it = v.begin(); it != v.end(); ++it) map[it->first] = XmlRpcToYaml(it->second);
      return map;
    }
    default:
      return YAML::Node();
  }
}

YAML::Node ParamsToYaml(const ros::NodeHandle& nh, const std::vector<std::string>& ros_only_keys) {
  XmlRpc::XmlRpcValue all;
  YAML::Node root(YAML::NodeType::Map);
  if (!nh.getParam(nh.getNamespace(), all) || all.getType() != XmlRpc::XmlRpcValue::TypeStruct) {
    return root;
  }
  for (auto it = all.begin(); it != all.end(); ++it) {
    if (std::find(ros_only_keys.begin(), ros_only_keys.end(), it->first) != ros_only_keys.end()) {
      continue;
    }
    root[it->first] = XmlRpcToYaml(it->second);
  }
  return root;
}

}  // namespace ipm_road_mapper
