// Converts ROS parameters (XmlRpc) into the YAML tree the core's options loaders read, so
// the nodelet and the offline runner share one schema and one validator.
#pragma once

#include <ros/node_handle.h>
#include <xmlrpcpp/XmlRpcValue.h>
#include <yaml-cpp/yaml.h>

#include <string>

namespace ipm_road_mapper {

// XmlRpc value -> YAML node (structs become maps, arrays sequences, scalars scalars).
YAML::Node XmlRpcToYaml(const XmlRpc::XmlRpcValue& value);

// All parameters under `nh`'s namespace, minus the keys in `ros_only_keys` (topics etc.
// that the ROS layer reads itself), as one YAML map.
YAML::Node ParamsToYaml(const ros::NodeHandle& nh, const std::vector<std::string>& ros_only_keys);

}  // namespace ipm_road_mapper
