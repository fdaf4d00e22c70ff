#include "ipm_road_mapper/pipeline/mapper_config.h"

#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <vector>

namespace ipm_road_mapper {
namespace {

namespace fs = std::filesystem;

std::string CheckQueueSize(const int& v) {
  return v >= 1 && v <= 100000 ? "" : "must be in [1, 100000] (got " + std::to_string(v) + ")";
}

std::string CheckFrameName(const std::string& v) {
  if (v.empty()) return "";
  if (v.find_first_of(" \t\n") != std::string::npos) return "must not contain spaces";
  if (v[0] == '/') return "must not start with '/' (tf2 frame ids have no leading slash)";
  return "";
}

std::string CheckNonEmpty(const std::string& v) { return v.empty() ? "must not be empty" : ""; }

std::string CheckFrameNameSet(const std::string& v) {
  return v.empty() ? "must not be empty" : CheckFrameName(v);
}

}  // namespace

RosOptions LoadRosOptions(OptionsReader reader) {
  RosOptions o;
  reader.Read<std::string>("mask_topic", &o.mask_topic, CheckNonEmpty);
  reader.Read<std::string>("mask_transport", &o.mask_transport, CheckNonEmpty);
  reader.Read<std::string>("camera_info_topic", &o.camera_info_topic, CheckNonEmpty);
  reader.Read<std::string>("image_topic", &o.image_topic);
  reader.Read<std::string>("odom_topic", &o.odom_topic, CheckNonEmpty);
  reader.Read<std::string>("sync", &o.sync, [](const std::string& v) -> std::string {
    return v == "exact" || v == "approximate" ? "" : "must be exact or approximate";
  });
  reader.Read<double>("publish_rate_hz", &o.publish_rate_hz, [](const double& v) {
    return v > 0.0 && v <= 100.0 ? "" : "must be in (0, 100] Hz";
  });
  reader.Read<std::string>("map_frame", &o.map_frame, CheckFrameNameSet);
  reader.Read<std::string>("odom_frame", &o.odom_frame, CheckFrameNameSet);
  reader.Read<bool>("publish_map_to_odom", &o.publish_map_to_odom);
  if (o.map_frame == o.odom_frame) {
    throw OptionsError(reader.KeyPath("odom_frame") + ": must differ from map_frame (" +
                       o.map_frame + "): map -> odom would be a frame's parent of itself");
  }
  reader.Read<std::string>("refined_camera_frame", &o.refined_camera_frame, CheckFrameName);
  reader.Read<std::string>("save_map_path", &o.save_map_path);
  reader.Read<std::string>("classes_file", &o.classes_file);
  reader.Read<int>("sync_queue_size", &o.sync_queue_size, CheckQueueSize);
  reader.Read<double>("approximate_sync_max_interval_s", &o.approximate_sync_max_interval_s,
                      CheckPositive);
  reader.Read<int>("odom_queue_size", &o.odom_queue_size, CheckQueueSize);
  reader.Read<double>("odometry_wait_s", &o.odometry_wait_s, CheckNonNegative);
  reader.Read<int>("path_max_poses", &o.path_max_poses, CheckPositiveInt);
  reader.Read<double>("diagnostics_period_s", &o.diagnostics_period_s, CheckPositive);
  reader.Read<double>("debug_image_rate_hz", &o.debug_image_rate_hz, CheckPositive);
  reader.Read<int>("input_queue_size", &o.input_queue_size, CheckQueueSize);
  reader.Read<double>("marker_full_period_s", &o.marker_full_period_s, CheckPositive);
  reader.Read<double>("vector_map_full_period_s", &o.vector_map_full_period_s, CheckPositive);
  reader.Read<double>("shutdown_budget_s", &o.shutdown_budget_s, CheckPositive);
  reader.Read<double>("autosave_period_s", &o.autosave_period_s, CheckNonNegative);
  reader.RejectUnknownKeys();
  return o;
}

MapperConfig LoadMapperConfig(OptionsReader reader) {
  MapperConfig config;
  config.geo_origin = LoadGeoOrigin(reader.Child("geo_origin"));
  config.ros = LoadRosOptions(reader.Child("ros"));
  // LoadMapperOptions takes its reader by value: the copy knows that geo_origin and ros
  // were read, so it rejects only keys that nobody asked for.
  config.mapper = LoadMapperOptions(reader);
  return config;
}

std::string CheckLiveConfig(const MapperConfig& config) {
  if (config.mapper.backend.synchronous) {
    return "backend.synchronous: true is for the offline runner only: the live nodelet would "
           "run every solve in its mapping thread and stall the input (set it false)";
  }
  return "";
}

MapperConfig LoadMapperConfigFile(const std::string& path) {
  try {
    return LoadMapperConfig(OptionsReader::FromFile(path));
  } catch (const OptionsError& e) {
    const std::string what = e.what();
    throw OptionsError(what.rfind(path, 0) == 0 ? what : path + ": " + what);
  }
}

std::string ToString(const RosOptions& o) {
  std::ostringstream s;
  auto or_default = [](const std::string& v, const char* fallback) {
    return v.empty() ? std::string(fallback) : v;
  };
  s << "ros.mask_topic: " << o.mask_topic << "\n"
    << "ros.camera_info_topic: " << o.camera_info_topic << "\n"
    << "ros.image_topic: " << or_default(o.image_topic, "(none)") << "\n"
    << "ros.odom_topic: " << o.odom_topic << "\n"
    << "ros.sync: " << o.sync << "\n"
    << "ros.mask_transport: " << o.mask_transport << "\n"
    << "ros.publish_rate_hz: " << o.publish_rate_hz << "\n"
    << "ros.map_frame: " << o.map_frame << "\n"
    << "ros.odom_frame: " << o.odom_frame << "\n"
    << "ros.publish_map_to_odom: " << (o.publish_map_to_odom ? "true" : "false") << "\n"
    << "ros.refined_camera_frame: " << or_default(o.refined_camera_frame, "(<camera>_refined)")
    << "\n"
    << "ros.save_map_path: " << or_default(o.save_map_path, "(none: not saved at shutdown)") << "\n"
    << "ros.classes_file: " << or_default(o.classes_file, "(package config/classes.yaml)") << "\n"
    << "ros.sync_queue_size: " << o.sync_queue_size << "\n"
    << "ros.approximate_sync_max_interval_s: " << o.approximate_sync_max_interval_s << "\n"
    << "ros.odom_queue_size: " << o.odom_queue_size << "\n"
    << "ros.odometry_wait_s: " << o.odometry_wait_s << "\n"
    << "ros.path_max_poses: " << o.path_max_poses << "\n"
    << "ros.diagnostics_period_s: " << o.diagnostics_period_s << "\n"
    << "ros.debug_image_rate_hz: " << o.debug_image_rate_hz << "\n"
    << "ros.input_queue_size: " << o.input_queue_size << "\n"
    << "ros.marker_full_period_s: " << o.marker_full_period_s << "\n"
    << "ros.vector_map_full_period_s: " << o.vector_map_full_period_s << "\n"
    << "ros.shutdown_budget_s: " << o.shutdown_budget_s << "\n"
    << "ros.autosave_period_s: " << o.autosave_period_s
    << (o.autosave_period_s > 0.0 ? "" : " (off: saved at shutdown only)") << "\n";
  return s.str();
}

std::string FindPackageFile(const std::string& package_path, const std::string& relative) {
  std::vector<std::string> roots;
  if (!package_path.empty()) roots.push_back(package_path);
  if (const char* source_dir = std::getenv("IRM_SOURCE_DIR")) roots.push_back(source_dir);
  std::error_code error;
  const fs::path exe = fs::read_symlink("/proc/self/exe", error);
  if (!error) roots.push_back((exe.parent_path() / "../../share/ipm_road_mapper").string());
  for (const std::string& root : roots) {
    if (fs::exists(fs::path(root) / relative)) return (fs::path(root) / relative).string();
  }
  throw OptionsError("cannot find the package's " + relative + " (set ROS_PACKAGE_PATH or " +
                     "IRM_SOURCE_DIR, or pass the file explicitly)");
}

}  // namespace ipm_road_mapper
