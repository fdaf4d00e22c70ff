// Offline runner: builds the vector map from a bag file, without a roscore.
//
//   rosrun ipm_road_mapper map_from_bag --bag <bag> [--config <yaml>] [--classes <yaml>]
//                                       [--async] --out <dir>
//
// The back end solves every window in turn (backend.synchronous forced on: offline the bag
// is read far faster than real time, and an owned optimizer thread would drop most
// windows); --async keeps the config's threading, as the nodelet runs it.
//
// Reads the mask, camera_info and odometry topics of the config's `input` section with the
// rosbag C++ API (masks and odometry read ahead in a thread: BagPrefetcher), pairs each mask with
// its camera_info (sync exact: identical stamp; approximate: nearest within half a frame period)
// and with odometry interpolated at its stamp (FrameAssembler, the same code the nodelet uses),
// runs the core Mapper, and writes <dir>/map.json, <dir>/map.geojson, <dir>/trajectory_tum.txt and
// <dir>/summary.txt. The rough extrinsic T_base_cam is the config's input.extrinsic when given,
// else the bag's /tf_static transform from input.base_frame to the mask's header.frame_id (a chain
// of static transforms is composed). Defaults: --config and --classes are config/mapper.yaml and
// config/classes.yaml of the package, found by rospack (ROS_PACKAGE_PATH), else under
// $IRM_SOURCE_DIR, else in the install space next to the executable (../../share/ipm_road_mapper).
// Exit status: 0 done; 2 bad input (missing bag, bad config, missing topic, no extrinsic, ...)
// with one error line on stderr; 1 an output could not be written.
#include <nav_msgs/Odometry.h>
#include <ros/package.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>

#include "ipm_road_mapper/pipeline/frame_assembler.h"
#include "ipm_road_mapper/core/io/geojson_export.h"
#include "ipm_road_mapper/core/mapper/mapper.h"
#include "ipm_road_mapper/core/geometry/rigid_transform.h"
#include "ipm_road_mapper/core/map/vector_map.h"
#include "ipm_road_mapper/ros/bag_input.h"
#include "ipm_road_mapper/ros/bag_prefetcher.h"
#include "ipm_road_mapper/pipeline/extrinsic_source.h"
#include "ipm_road_mapper/pipeline/map_files.h"
#include "ipm_road_mapper/pipeline/mapper_config.h"
#include "ipm_road_mapper/pipeline/mapping_session.h"
#include "ipm_road_mapper/ros/msg_conversion.h"
#include "ipm_road_mapper/pipeline/progress_meter.h"

namespace ipm_road_mapper {
namespace {

namespace fs = std::filesystem;

constexpr const char* kUsage =
    "usage: map_from_bag --bag <bag> [--config <mapper.yaml>] [--classes <classes.yaml>] "
    "[--async] --out <dir>";

// Bad input: reported as one line, exit status 2.
struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct Arguments {
  std::string bag, config, classes, out;
  bool async = false;  // keep backend.synchronous as configured (live-like timing)
};

// A file of the package (e.g. "config/mapper.yaml"); see the file comment for the search.
std::string PackageFile(const std::string& relative) {
  try {
    return FindPackageFile(ros::package::getPath("ipm_road_mapper"), relative);
  } catch (const OptionsError& e) {
    throw InputError(e.what());
  }
}

Arguments ParseArguments(int argc, char** argv) {
  Arguments args;
  for (int i = 1; i < argc; ++i) {
    const std::string flag = argv[i];
    if (flag == "--async") {
      args.async = true;
      continue;
    }
    if (flag == "-h" || flag == "--help") {
      std::cout << kUsage << "\n";
      std::exit(0);
    }
    std::string* target = flag == "--bag"       ? &args.bag
                          : flag == "--config"  ? &args.config
                          : flag == "--classes" ? &args.classes
                          : flag == "--out"     ? &args.out
                                                : nullptr;
    if (!target) throw InputError("unknown argument '" + flag + "'; " + kUsage);
    if (i + 1 >= argc) throw InputError(flag + " needs a value; " + kUsage);
    *target = argv[++i];
  }
  if (args.bag.empty() || args.out.empty()) throw InputError(std::string(kUsage));
  if (args.config.empty()) args.config = PackageFile("config/mapper.yaml");
  if (args.classes.empty()) args.classes = PackageFile("config/classes.yaml");
  return args;
}

// Loads the config (mapper options, geo_origin, the nodelet's `ros` section: the same loader
// as the nodelet's, see mapper_config.h).
MapperConfig LoadConfig(const std::string& path) {
  try {
    return LoadMapperConfigFile(path);
  } catch (const OptionsError& e) {
    throw InputError(e.what());
  }
}

// The rough extrinsic and where it came from (ChooseExtrinsic, as the nodelet decides it).
Eigen::Isometry3d FindExtrinsic(const rosbag::Bag& bag, const InputOptions& input,
                                const std::string& mask_topic, std::string* source) {
  std::string camera_frame;
  if (!input.T_base_cam) {
    rosbag::View masks(bag, rosbag::TopicQuery(mask_topic));
    if (masks.size() == 0) throw InputError("topic " + mask_topic + " has no message");
    const auto first = masks.begin()->instantiate<sensor_msgs::Image>();
    camera_frame = first ? first->header.frame_id : "";
  }
  const TransformLookup lookup = [&bag](const std::string& parent, const std::string& child,
                                        Eigen::Isometry3d* T) {
    return LookupStaticTransform(bag, parent, child, T);
  };
  ExtrinsicChoice choice;
  const std::string error = ChooseExtrinsic(input, camera_frame, lookup, "/tf_static", &choice);
  if (!error.empty()) {
    throw InputError(error + "; set input.extrinsic in the config or record /tf_static");
  }
  *source = choice.source;
  return choice.T_base_cam;
}

// What the run did, for summary.txt.
struct RunStats {
  std::size_t frames_read = 0;
  double bag_span_s = 0.0;
  double wall_s = 0.0;
  std::string extrinsic_source;
};

// One line about the optimizer: windows, solve time, how far the extrinsic moved.
std::string BackendLine(const Mapper& mapper) {
  if (!mapper.options().backend.enabled) return "back end: disabled";
  const BackendStats stats = mapper.backend_stats();
  double total_s = 0.0;
  for (double t : stats.solve_times_s) total_s += t;
  const Eigen::Isometry3d change = mapper.T_base_cam_initial().inverse() * mapper.T_base_cam();
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(3);
  s << "back end: " << stats.submitted << " windows submitted, " << stats.solved << " solved, "
    << stats.dropped_queue_full << " dropped (queue full), " << stats.unusable << " unusable; "
    << "solve time " << total_s << " s total; results applied " << mapper.counters().results_applied
    << ", rejected " << mapper.counters().results_rejected << "; extrinsic moved "
    << RotationAngleBetween(mapper.T_base_cam_initial(), mapper.T_base_cam()) * 180.0 / M_PI
    << " deg, " << change.translation().norm() << " m";
  return s.str();
}

// One line about the front end's time per frame (the caller's thread).
std::string FrontEndLine(const Mapper& mapper) {
  const FrontEndTiming& t = mapper.frontend_timing();
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(2);
  s << "front end: " << Quantile(t.total_ms, 0.5) << " ms/frame median, "
    << Quantile(t.total_ms, 0.95) << " ms p95, " << Quantile(t.total_ms, 1.0)
    << " ms max (extraction " << Quantile(t.extraction_ms, 0.5) << " ms median)";
  return s.str();
}

std::string Summary(const Arguments& args, const Mapper& mapper, const FrameAssembler& assembler,
                    const VectorMap& map, const RunStats& stats) {
  const MapperCounters& c = mapper.counters();
  const FrameAssemblerCounters& a = assembler.counters();
  const ExtractionCounters& e = c.extraction;
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(2);
  s << "bag: " << args.bag << "\nconfig: " << args.config << " (method " << mapper.options().method
    << ")\nclasses: " << args.classes << "\nextrinsic: " << stats.extrinsic_source << "\n"
    << "frames read: " << stats.frames_read << "\nframes used: " << c.frames_used
    << "\nframes skipped: " << c.SkippedTotal() << "\n";
  for (const auto& [reason, count] : c.frames_skipped) s << "  " << reason << ": " << count << "\n";
  s << "odometry: " << a.odometry_received << " received, " << a.odometry_used << " used, "
    << a.bad_odometry << " bad, " << a.odometry_out_of_order
    << " out of order; time jumps: " << a.time_jumps << "\n"
    << "extraction: " << e.instances_seen << " instances; dropped: unknown class "
    << e.dropped_unknown_class << ", tiny " << e.dropped_tiny << ", border " << e.dropped_border
    << ", range " << e.dropped_range << ", degenerate " << e.dropped_degenerate
    << ", instance limit " << e.dropped_instance_limit << "\n"
    << "map: " << map.markings.size() << " markings, " << map.lanes.size() << " lanes (created "
    << c.markings_created << " markings, " << c.lanes_created << " lanes; spurious dropped "
    << c.spurious_dropped << ", lanes merged " << c.lanes_merged << ", lane observations unused "
    << c.lane_observations_unused << ", near a lane " << c.lane_observations_near_lane << ")\n"
    << BackendLine(mapper) << "\n"
    << FrontEndLine(mapper) << "\n"
    << "wall time: " << stats.wall_s << " s; "
    << (stats.wall_s > 0 ? stats.frames_read / stats.wall_s : 0.0) << " frames/s; bag span "
    << stats.bag_span_s << " s; real-time factor "
    << (stats.wall_s > 0 ? stats.bag_span_s / stats.wall_s : 0.0) << "x\n"
    << "outputs: " << args.out << "/{map.json, map.geojson, trajectory_tum.txt, summary.txt}\n";
  return s.str();
}

// Hands a mask message to the session, or counts why it cannot be a frame.
void AddMask(const sensor_msgs::Image& msg, const CameraInfoTable& camera_infos, bool exact_sync,
             MappingSession* session) {
  cv::Mat mask;
  std::string error = ImageToMask(msg, &mask);
  if (!error.empty()) {
    session->CountSkipped("bad_mask_encoding: " + error, nullptr);
    return;
  }
  CameraIntrinsics camera;
  error = camera_infos.Match(msg.header.stamp, exact_sync, &camera);
  if (!error.empty()) {
    session->CountSkipped(error, nullptr);
    return;
  }
  session->AddFrame(ToSeconds(msg.header.stamp), std::move(mask), camera, nullptr);
}

void WriteOutputs(const std::string& dir, const VectorMap& map,
                  const std::optional<GeoOrigin>& geo_origin, const std::string& summary) {
  SaveMapFiles(map, geo_origin, MapFilePathsInFolder(dir));
  std::ofstream out(dir + "/summary.txt");
  out << summary;
  if (!out) throw std::runtime_error(dir + "/summary.txt: cannot write");
}

int Run(int argc, char** argv) {
  const Arguments args = ParseArguments(argc, argv);
  MapperConfig config = LoadConfig(args.config);
  // Offline, every window is solved in turn (the bag is read far faster than real time, so
  // an owned thread would drop most of them); --async keeps the config's threading.
  if (!args.async) config.mapper.backend.synchronous = true;
  const MapperOptions& options = config.mapper;
  ClassTable classes;
  try {
    classes = ClassTable::LoadFile(args.classes);
  } catch (const OptionsError& e) {
    throw InputError(e.what());
  }
  if (!fs::is_regular_file(args.bag)) throw InputError(args.bag + ": no such bag file");
  rosbag::Bag bag;
  try {
    bag.open(args.bag, rosbag::bagmode::Read);
  } catch (const rosbag::BagException& e) {
    throw InputError(args.bag + ": cannot read bag: " + e.what());
  }
  const InputOptions& input = options.input;
  const RosOptions& topics = config.ros;  // the bag's topic names and sync, as the nodelet's
  const std::string topic_error =
      CheckBagTopics(bag, {{topics.mask_topic, "sensor_msgs/Image"},
                           {topics.camera_info_topic, "sensor_msgs/CameraInfo"},
                           {topics.odom_topic, "nav_msgs/Odometry"}});
  if (!topic_error.empty()) throw InputError(args.bag + ": " + topic_error);
  RunStats stats;
  const Eigen::Isometry3d T_base_cam =
      FindExtrinsic(bag, input, topics.mask_topic, &stats.extrinsic_source);
  std::error_code dir_error;
  fs::create_directories(args.out, dir_error);
  if (dir_error || !fs::is_directory(args.out)) {
    throw InputError(args.out + ": cannot create output folder: " + dir_error.message());
  }

  const CameraInfoTable camera_infos = CameraInfoTable::Read(bag, topics.camera_info_topic);
  const bool exact_sync = topics.sync == "exact";
  // The same pipeline as the nodelet's; no odometry wait rule offline (the bag is complete).
  MappingSession session(options, classes);
  session.Start(T_base_cam);
  rosbag::View span_view(bag, rosbag::TopicQuery({topics.mask_topic, topics.odom_topic}));
  const std::size_t total_masks = rosbag::View(bag, rosbag::TopicQuery(topics.mask_topic)).size();
  std::cerr << "map_from_bag: " << total_masks << " masks, " << camera_infos.size()
            << " camera_infos; extrinsic from " << stats.extrinsic_source << "\n";

  ProgressMeter progress(total_masks, "frames");
  const auto start = std::chrono::steady_clock::now();
  {
    // The bag is read and deserialized ahead, in its own thread; mapping stays in this one.
    BagPrefetcher prefetcher(bag, topics.mask_topic, topics.odom_topic);
    BagPrefetcher::Item message;
    while (prefetcher.Next(&message)) {
      if (!message.is_mask) {
        StampedPose pose;
        // An unconvertible message (e.g. a zero quaternion) is handed on as a NaN pose, so
        // the assembler counts it as bad_odometry like any other invalid pose.
        if (!message.odometry || !OdometryToStampedPose(*message.odometry, &pose).empty()) {
          pose.T_map_base.matrix().setConstant(std::numeric_limits<double>::quiet_NaN());
        }
        session.AddOdometry(pose, nullptr);
      } else {
        if (message.mask) {
          AddMask(*message.mask, camera_infos, exact_sync, &session);
        } else {
          session.CountSkipped("bad_mask_message: not a sensor_msgs/Image", nullptr);
        }
        progress.Update(++stats.frames_read);
      }
    }
  }
  session.Finish(nullptr);  // waiting frames decided, the last window's solve merged
  progress.Finish();
  stats.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  stats.bag_span_s = (span_view.getEndTime() - span_view.getBeginTime()).toSec();

  const Mapper& mapper = *session.mapper();
  VectorMap map = mapper.ExportMap();
  map.metadata["bag"] = args.bag;
  map.metadata["config"] = args.config;
  map.metadata["extrinsic_source"] = stats.extrinsic_source;
  const std::string summary = Summary(args, mapper, session.assembler(), map, stats);
  try {
    WriteOutputs(args.out, map, config.geo_origin, summary);
  } catch (const std::exception& e) {
    std::cerr << "map_from_bag: error: " << e.what() << "\n";
    return 1;
  }
  std::cout << summary;
  return 0;
}

}  // namespace
}  // namespace ipm_road_mapper

int main(int argc, char** argv) {
  ros::Time::init();
  try {
    return ipm_road_mapper::Run(argc, argv);
  } catch (const ipm_road_mapper::InputError& e) {
    std::cerr << "map_from_bag: error: " << e.what() << "\n";
    return 2;
  } catch (const rosbag::BagException& e) {
    std::cerr << "map_from_bag: error: bag read failed: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "map_from_bag: error: " << e.what() << "\n";
    return 1;
  }
}
