// Runs MapperNodelet as a standalone node, for users who do not run a nodelet manager:
//
//   rosparam load config/mapper.yaml /ipm_road_mapper   (and config/ros.yaml, optional)
//   rosrun ipm_road_mapper mapper_node [__name:=<name>]
//
// Parameters, topics and services are those of the nodelet (docs/ros_api.md), in the
// node's private namespace. `--help` (or -h) prints this usage and exits 0 without
// starting a node. Exit status 1 when the nodelet refuses its parameters.
#include <nodelet/loader.h>
#include <ros/ros.h>

#include <cstring>
#include <iostream>

namespace {

// True when the command line asks for the usage.
bool WantsHelp(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--help") == 0 || std::strcmp(argv[i], "-h") == 0) return true;
  }
  return false;
}

}  // namespace

int main(int argc, char** argv) {
  if (WantsHelp(argc, argv)) {
    std::cout
        << "usage: rosrun ipm_road_mapper mapper_node [__name:=<name>] [<topic>:=<topic> ...]\n\n"
           "Runs the MapperNodelet as a standalone node (a roscore must run). It takes no "
           "options: its parameters (rosparam load config/mapper.yaml /ipm_road_mapper),\n"
           "topics, services and their defaults are those of the nodelet, in the node's "
           "private namespace: docs/ros_api.md.\n\n"
           "options:\n  -h [ --help ]   print this help and exit\n";
    return 0;
  }
  ros::init(argc, argv, "ipm_road_mapper");
  // No manager services: this process hosts exactly this nodelet.
  nodelet::Loader loader(false);
  const nodelet::M_string remappings(ros::names::getRemappings());
  const nodelet::V_string my_argv(argv + 1, argv + argc);
  if (!loader.load(ros::this_node::getName(), "ipm_road_mapper/MapperNodelet", remappings,
                   my_argv)) {
    ROS_FATAL("failed to load ipm_road_mapper/MapperNodelet (see the error above)");
    return 1;
  }
  ros::spin();
  loader.clear();  // unload (and save the map when ros/save_map_path is set) before exit
  return 0;
}
