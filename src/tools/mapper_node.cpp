// Runs MapperNodelet as a standalone node, for users who do not run a nodelet manager:
//
//   rosparam load config/mapper.yaml /ipm_road_mapper   (and config/ros.yaml, optional)
//   rosrun ipm_road_mapper mapper_node [__name:=<name>]
//
// Parameters, topics and services are those of the nodelet (docs/ros_api.md), in the
// node's private namespace. Exit status 1 when the nodelet refuses its parameters.
#include <nodelet/loader.h>
#include <ros/ros.h>

int main(int argc, char** argv) {
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
