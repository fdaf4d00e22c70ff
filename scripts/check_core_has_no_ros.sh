#!/usr/bin/env bash
# Fails when a file of a ROS-free library (core, pipeline, sim, eval, segmentation) includes a ROS header.
# They (Eigen, OpenCV, Ceres, yaml-cpp, nlohmann_json) must build and be usable without ROS.
repo="${1:-$(cd "$(dirname "$0")/.." && pwd)}"
pattern='#\s*include\s*[<"](ros/|roscpp|rosbag/|nodelet/|pluginlib/|tf2|tf2_ros/|tf/|cv_bridge/|image_transport/|message_filters/|sensor_msgs/|nav_msgs/|geometry_msgs/|std_msgs/|visualization_msgs/|diagnostic_updater/|ipm_road_mapper/ros/|ipm_road_mapper/[A-Z][A-Za-z]*\.h)'
dirs=()
for layer in core pipeline sim eval segmentation; do
  dirs+=("$repo/include/ipm_road_mapper/$layer" "$repo/src/$layer")
done
hits=$(grep -rnE "$pattern" "${dirs[@]}" 2>/dev/null)
if [ -n "$hits" ]; then
  echo "ROS headers found in a ROS-free library:"
  echo "$hits"
  exit 1
fi
count=$(find "${dirs[@]}" -type f | wc -l)
echo "core, pipeline, sim, eval, segmentation: $count files, no ROS include"
