#include "ipm_road_mapper/ros/mapper_nodelet.h"

#include <pluginlib/class_list_macros.hpp>
#include <ros/ros.h>

#include "ipm_road_mapper/ros/param_bridge.h"

namespace ipm_road_mapper {

void MapperNodelet::onInit() {
  ros::NodeHandle& private_nh = getPrivateNodeHandle();
  try {
    options_ = LoadMapperOptions(OptionsReader(ParamsToYaml(private_nh, {}), ""));
  } catch (const OptionsError& e) {
    NODELET_FATAL("invalid parameter %s: %s", private_nh.getNamespace().c_str(), e.what());
    throw;  // refuse to start: the manager reports the failed load
  }
  NODELET_INFO_STREAM("ipm_road_mapper options:\n" << ToString(options_));
}

}  // namespace ipm_road_mapper

PLUGINLIB_EXPORT_CLASS(ipm_road_mapper::MapperNodelet, nodelet::Nodelet)
