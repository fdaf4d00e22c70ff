// Runs MapperNodelet as a standalone node (`rosrun ipm_road_mapper mapper_node`), for
// users who do not run a nodelet manager.
#include <nodelet/loader.h>
#include <ros/ros.h>

int main(int argc, char** argv) {
  ros::init(argc, argv, "ipm_road_mapper");
  nodelet::Loader loader;
  nodelet::M_string remappings(ros::names::getRemappings());
  nodelet::V_string my_argv(argv + 1, argv + argc);
  if (!loader.load(ros::this_node::getName(), "ipm_road_mapper/MapperNodelet", remappings,
                   my_argv)) {
    ROS_FATAL("failed to load ipm_road_mapper/MapperNodelet");
    return 1;
  }
  ros::spin();
  return 0;
}
