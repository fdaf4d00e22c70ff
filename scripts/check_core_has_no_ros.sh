#!/usr/bin/env bash
# Fails when a file of the core library includes a ROS header. The core (Eigen, OpenCV,
# Ceres, yaml-cpp, nlohmann_json) must build and be usable without ROS.
repo="${1:-$(cd "$(dirname "$0")/.." && pwd)}"
pattern='#\s*include\s*[<"](ros/|roscpp|rosbag/|nodelet/|pluginlib/|tf2|tf2_ros/|tf/|cv_bridge/|image_transport/|message_filters/|sensor_msgs/|nav_msgs/|geometry_msgs/|std_msgs/|visualization_msgs/|diagnostic_updater/|ipm_road_mapper/ros/|ipm_road_mapper/[A-Z][A-Za-z]*\.h)'
hits=$(grep -rnE "$pattern" "$repo/include/ipm_road_mapper/core" "$repo/src/core" 2>/dev/null)
if [ -n "$hits" ]; then
  echo "ROS headers found in the core library:"
  echo "$hits"
  exit 1
fi
count=$(find "$repo/include/ipm_road_mapper/core" "$repo/src/core" -type f | wc -l)
echo "core: $count files, no ROS include"
