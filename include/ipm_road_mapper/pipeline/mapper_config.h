// The whole mapper configuration as both runners read it (config/mapper.yaml, or the
// nodelet's private parameters turned into the same YAML tree): the core's MapperOptions,
// the optional geo origin of the GeoJSON export, and the ROS-only `ros:` section. One
// loader, one validator: an unknown key or a bad value anywhere is an OptionsError naming
// the key path, for map_from_bag and the nodelet alike. No ROS header.
#pragma once

#include <optional>
#include <string>

#include "ipm_road_mapper/core/io/geojson_export.h"
#include "ipm_road_mapper/core/io/yaml_options.h"
#include "ipm_road_mapper/core/mapper/mapper_options.h"

namespace ipm_road_mapper {

// The `ros:` section (config/ros.yaml): what only the live nodelet uses (the offline runner
// validates it too when a config holds it). Defaults are those of docs/ros_api.md and of
// config/ros.yaml (a test checks that they agree).
struct RosOptions {
  std::string mask_topic = "/camera/instances";  // sensor_msgs/Image, 16UC1 masks
  // How masks arrive: "raw" (sensor_msgs/Image), "compressed" (png on <mask_topic>/compressed)
  // or another installed image_transport plugin's name.
  std::string mask_transport = "raw";
  std::string camera_info_topic = "/camera/camera_info";
  std::string image_topic = "/camera/image_raw";  // optional ("" = none), debug overlay only
  std::string odom_topic = "/odom";               // nav_msgs/Odometry
  std::string sync = "exact";                     // exact | approximate (mask <-> camera_info)
  double publish_rate_hz = 2.0;  // ~vector_map_delta, ~markers, ~corrected_path, refined tf
  // REP-105 frames, named as robot_localization names them: the map and everything
  // corrected is in map_frame (also map.json's frame_id, offline and live); the odometry is
  // in odom_frame; with publish_map_to_odom the nodelet broadcasts map_frame -> odom_frame
  // (the correction), so that map_frame -> base_link is the corrected pose.
  std::string map_frame = "map";
  std::string odom_frame = "odom";
  bool publish_map_to_odom = true;
  std::string refined_camera_frame;  // tf child of the refined extrinsic; "" = <camera>_refined
  std::string save_map_path;         // the map is written here (autosave, shutdown) when set
  std::string classes_file;          // class table; "" = the package's config/classes.yaml
  int sync_queue_size = 10;          // message_filters queue of mask <-> camera_info pairing
  double approximate_sync_max_interval_s = 0.025;  // sync: approximate, largest stamp gap
  int odom_queue_size = 200;                       // subscriber queue of odometry
  // A frame waiting this long (mask stamps) for odometry is decided at once (skipped), so
  // missing odometry shows in the counters without waiting for the queue to overflow.
  double odometry_wait_s = 1.0;
  int path_max_poses = 5000;  // ~corrected_path keeps the newest this many poses
  // ~debug_image at most this often; each overlay exports the map as of its frame (only
  // while someone subscribes).
  double debug_image_rate_hz = 5.0;
  double diagnostics_period_s = 1.0;
  // Inputs (frames, odometry, debug images) waiting for the mapping thread; when full the
  // oldest is dropped and counted.
  int input_queue_size = 500;
  // ~markers: the full marker set is re-sent this often (and to every new subscriber);
  // in between only what changed.
  double marker_full_period_s = 10.0;
  // ~vector_map (the whole map) is published this often; ~vector_map_delta carries the
  // changes at publish_rate_hz in between.
  double vector_map_full_period_s = 10.0;
  // Unload / shutdown with save_map_path: the time the last solve may take before the
  // latest snapshot is saved instead.
  double shutdown_budget_s = 3.0;
  // With save_map_path: the latest snapshot is also saved this often (s, wall time) by an
  // owned saver thread, so a crash loses at most one period; 0 = only at shutdown.
  double autosave_period_s = 30.0;
};

// Everything a runner is configured with.
struct MapperConfig {
  MapperOptions mapper;
  std::optional<GeoOrigin> geo_origin;
  RosOptions ros;
};

// Reads the `ros` section; throws OptionsError naming the bad key.
RosOptions LoadRosOptions(OptionsReader reader);

// Reads a whole config (geo_origin, ros, then every core section; unknown keys are
// errors). Throws OptionsError.
MapperConfig LoadMapperConfig(OptionsReader reader);

// Why the live nodelet cannot run this config ("" = it can): a synchronous back end would
// solve in the mapping thread and stall the input.
std::string CheckLiveConfig(const MapperConfig& config);

// Loads a config file (a `base:` file is overlaid first); errors are prefixed with the path.
MapperConfig LoadMapperConfigFile(const std::string& path);

// A multi-line dump of the `ros` section (printed at start-up next to ToString(options)).
std::string ToString(const RosOptions& options);

// A file of the package, e.g. "config/classes.yaml", searched in `package_path` (rospack's
// answer, may be empty), then $IRM_SOURCE_DIR, then the install space next to the running
// executable (../../share/ipm_road_mapper). Throws OptionsError when it is nowhere.
std::string FindPackageFile(const std::string& package_path, const std::string& relative);

}  // namespace ipm_road_mapper
