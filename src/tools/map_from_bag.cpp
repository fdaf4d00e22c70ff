// Offline runner: builds the vector map from a bag file, without a roscore.
//
//   rosrun ipm_road_mapper map_from_bag --bag <bag> [--config <yaml>] [--classes <yaml>]
//                                       [--async] --out <dir> [--stats-out <csv>]
//                                       [--publish-stats-out <csv>]
//                                       [--callgrind-spans <t0:t1,...>]
//
// The back end solves every window in turn (backend.synchronous forced on: offline the bag
// is read far faster than real time, and an owned optimizer thread would drop most
// windows); --async keeps the config's threading, as the nodelet runs it.
//
// Reads the mask, camera_info and odometry topics of the config's `input` section with the
// rosbag C++ API in one pass (read ahead in a thread: BagPrefetcher; mapping starts with the
// first messages), pairs each mask with its camera_info (CameraInfoPairing; sync exact:
// identical stamp; approximate: nearest within half the period of the first camera_infos)
// and with odometry interpolated at its stamp (FrameAssembler, the same code the nodelet
// uses), runs the core Mapper, and writes <dir>/map.json, <dir>/map.geojson and <dir>/map.osm
// (Lanelet2; both only with a geo_origin),
// <dir>/map_trajectory_tum.txt and <dir>/summary.txt (with startup_s: process start to the first
// frame mapped), with --stats-out a CSV row per frame (CPU time, RSS), and with
// --publish-stats-out the publication's CPU per publish near each km (PublishCostProbe); under
// valgrind, --callgrind-spans counts the instructions of chosen spans of frames
// (InstructionSpans, scripts/benchmark.sh --long --instructions). The rough
// extrinsic T_base_cam is the config's input.extrinsic when given, else the bag's /tf_static
// transform from input.base_frame to the mask's header.frame_id (a chain of static transforms
// is composed). Defaults: --config and --classes are config/mapper.yaml and
// config/classes.yaml of the package, found by rospack (ROS_PACKAGE_PATH), else under
// $IRM_SOURCE_DIR, else in the install space next to the executable
// (../../share/ipm_road_mapper). A damaged bag maps what can be read: a message of an
// unreadable chunk is skipped and counted, and the lost time spans are printed and written to
// the summary and map.json; a bag without its index (cut short, or never closed), which
// rosbag's C++ API cannot open, is read in record order past the missing index into a
// temporary indexed copy in <dir> (SalvageUnindexedBag; removed at exit), one line says so,
// and the copy is mapped; only when that fails too does one line suggest `rosbag reindex
// <bag>`, exit 2. Exit status: 0 done
// (or --help); 2 bad input (bad command line, missing bag, bad config, missing topic, no extrinsic,
// ...) with one error line on stderr; 1 an output could not be written.
#include <ros/package.h>
#include <rosbag/view.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

#include "ipm_road_mapper/core/io/geojson_export.h"
#include "ipm_road_mapper/core/map/vector_map.h"
#include "ipm_road_mapper/core/mapper/mapper.h"
#include "ipm_road_mapper/pipeline/command_line.h"
#include "ipm_road_mapper/pipeline/extrinsic_source.h"
#include "ipm_road_mapper/pipeline/frame_assembler.h"
#include "ipm_road_mapper/pipeline/instruction_spans.h"
#include "ipm_road_mapper/pipeline/map_files.h"
#include "ipm_road_mapper/pipeline/mapper_config.h"
#include "ipm_road_mapper/pipeline/mapping_session.h"
#include "ipm_road_mapper/pipeline/process_stats.h"
#include "ipm_road_mapper/pipeline/progress_meter.h"
#include "ipm_road_mapper/ros/bag_input.h"
#include "ipm_road_mapper/ros/bag_mapping.h"
#include "ipm_road_mapper/ros/bag_read_loss.h"
#include "ipm_road_mapper/ros/bag_run_summary.h"
#include "ipm_road_mapper/ros/publish_cost_probe.h"
#include "ipm_road_mapper/ros/unindexed_bag.h"

namespace ipm_road_mapper {
namespace {

namespace fs = std::filesystem;

// Bad input: reported as one line, exit status 2.
struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct Arguments {
  std::string bag, config, classes, out;
  std::string stats_out;          // empty: no per-frame stats file
  std::string publish_stats_out;  // empty: no publish-cost CSV
  std::string calibration_out;    // empty: no calibration file
  std::string callgrind_spans;    // empty: no instruction counting
  bool async = false;             // keep backend.synchronous as configured (live-like timing)
};

// A file of the package (e.g. "config/mapper.yaml"); see the file comment for the search.
std::string PackageFile(const std::string& relative) {
  try {
    return FindPackageFile(ros::package::getPath("ipm_road_mapper"), relative);
  } catch (const OptionsError& e) {
    throw InputError(e.what());
  }
}

// Parses the command line (pipeline/command_line.h): the exit code when the tool stops
// there (--help: 0, a bad command line: 2), else nullopt with *args filled in.
std::optional<int> ParseArguments(int argc, char** argv, Arguments* args) {
  CommandLine line("map_from_bag",
                   "Builds the vector map from a bag file, without a roscore "
                   "(docs/map_from_bag.md).");
  line.Required("bag", "<bag>", &args->bag, "the bag to map")
      .Optional("config", "<mapper.yaml>", &args->config, "config/mapper.yaml of the package",
                "mapper config (may start with `base: <file>`)")
      .Optional("classes", "<classes.yaml>", &args->classes, "config/classes.yaml of the package",
                "mask class table")
      .Flag("async", &args->async,
            "keep the config's back-end threading (as live) instead of solving every window "
            "in turn")
      .Required("out", "<dir>", &args->out, "output folder (created if needed)")
      .Optional("stats-out", "<file>", &args->stats_out, "none",
                "per-frame CSV frame,stamp,cpu_s,rss_kb (docs/map_from_bag.md)")
      .Optional("publish-stats-out", "<file>", &args->publish_stats_out, "none",
                "CSV of the map publication's CPU per publish near each whole km, built from "
                "the incremental export and the old whole-map way (docs/map_from_bag.md)")
      .Optional("calibration-out", "<file.yaml>", &args->calibration_out, "none",
                "the refined extrinsic as a config whose input.extrinsic the next run reads, "
                "with a static_transform_publisher line and a URDF joint (docs/map_from_bag.md)")
      .Optional("callgrind-spans", "<t0:t1,...>", &args->callgrind_spans, "none",
                "under valgrind --tool=callgrind --instr-atstart=no: count the instructions of "
                "the frames in these stamp spans, one callgrind dump per span "
                "(pipeline/instruction_spans.h)");
  return line.ParseOrExitCode(argc, argv);
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
Eigen::Isometry3d FindExtrinsic(rosbag::Bag* bag_ptr, const InputOptions& input,
                                const std::string& mask_topic, std::string* source,
                                std::string* camera_frame_out) {
  const rosbag::Bag& bag = *bag_ptr;
  std::string camera_frame;
  if (!input.T_base_cam) {
    if (rosbag::View(bag, rosbag::TopicQuery(mask_topic)).size() == 0) {
      throw InputError("topic " + mask_topic + " has no message");
    }
    camera_frame = FirstReadableMaskFrame(bag_ptr, mask_topic);
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
  *camera_frame_out = camera_frame;
  return choice.T_base_cam;
}

void WriteOutputs(const std::string& dir, const VectorMap& map,
                  const std::optional<GeoOrigin>& geo_origin, const std::string& summary) {
  const std::string note = SaveMapFiles(map, geo_origin, MapFilePathsInFolder(dir));
  if (!note.empty()) std::cout << note << "\n";
  std::ofstream out(dir + "/summary.txt");
  out << summary;
  if (!out) throw std::runtime_error(dir + "/summary.txt: cannot write");
}

int Run(int argc, char** argv) {
  Arguments args;
  if (const std::optional<int> exit_code = ParseArguments(argc, argv, &args)) return *exit_code;
  if (args.config.empty()) args.config = PackageFile("config/mapper.yaml");
  if (args.classes.empty()) args.classes = PackageFile("config/classes.yaml");
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
  BagRunStats stats;
  OpenedBag opened;  // the bag, or the indexed copy of one without its index
  if (const std::string error = opened.Open(args.bag, args.out); !error.empty()) {
    throw InputError(error);
  }
  rosbag::Bag& bag = opened.bag();
  if (opened.salvage()) {
    const BagSalvage& salvage = *opened.salvage();
    stats.index_problem = opened.index_problem();
    stats.salvage = salvage;
    std::cerr << "map_from_bag: " << args.bag << ": " << opened.index_problem()
              << ": read past the missing index in record order (" << salvage.messages
              << " messages in " << salvage.chunks << " chunks; " << salvage.end
              << "); mapping what it holds\n";
  }
  const InputOptions& input = options.input;
  const RosOptions& topics = config.ros;  // the bag's topic names and sync, as the nodelet's
  const std::string topic_error =
      CheckBagTopics(bag, {{topics.mask_topic, "sensor_msgs/Image"},
                           {topics.camera_info_topic, "sensor_msgs/CameraInfo"},
                           {topics.odom_topic, "nav_msgs/Odometry"}});
  if (!topic_error.empty()) throw InputError(args.bag + ": " + topic_error);
  const Eigen::Isometry3d T_base_cam =
      FindExtrinsic(&bag, input, topics.mask_topic, &stats.extrinsic_source, &stats.camera_frame);
  std::error_code dir_error;
  fs::create_directories(args.out, dir_error);
  if (dir_error || !fs::is_directory(args.out)) {
    throw InputError(args.out + ": cannot create output folder: " + dir_error.message());
  }
  // Opened before mapping, so an unwritable path fails at once (exit 1).
  std::optional<FrameStatsWriter> frame_stats;
  if (!args.stats_out.empty()) frame_stats.emplace(args.stats_out);
  std::optional<PublishCostProbe> publish_probe;  // an unwritable path: exit 1, as above
  if (!args.publish_stats_out.empty()) {
    publish_probe.emplace(args.publish_stats_out, config.ros.publish_rate_hz);
  }

  std::optional<InstructionSpans> instruction_spans;
  if (!args.callgrind_spans.empty()) {
    std::vector<StampSpan> spans;
    try {
      spans = ParseStampSpans(args.callgrind_spans);
    } catch (const std::invalid_argument& e) {
      throw InputError(std::string("--callgrind-spans: ") + e.what());
    }
    InstructionCounterHooks hooks;
    if (const std::string reason = CallgrindHooks(&hooks); !reason.empty()) {
      throw InputError("--callgrind-spans: " + reason);
    }
    instruction_spans.emplace(std::move(spans), std::move(hooks));
  }

  // The same pipeline as the nodelet's; no odometry wait rule offline (the bag is complete).
  MappingSession session(options, classes);
  session.Start(T_base_cam);
  // Counts and span from the bag's index (no message is read).
  rosbag::View span_view(bag, rosbag::TopicQuery({topics.mask_topic, topics.odom_topic}));
  const std::size_t total_masks = rosbag::View(bag, rosbag::TopicQuery(topics.mask_topic)).size();
  const std::size_t total_camera_infos =
      rosbag::View(bag, rosbag::TopicQuery(topics.camera_info_topic)).size();
  std::cerr << "map_from_bag: " << total_masks << " masks, " << total_camera_infos
            << " camera_infos; extrinsic from " << stats.extrinsic_source << "\n";

  ProgressMeter progress(total_masks, "frames");
  const auto start = std::chrono::steady_clock::now();
  BagMappingCallbacks callbacks;
  callbacks.frame_done = [&](std::size_t frame, double stamp) {
    if (frame_stats) frame_stats->Add(frame, stamp);
    if (instruction_spans) instruction_spans->OnFrameDone(stamp);
    if (publish_probe) publish_probe->OnFrame(*session.mapper(), frame, stamp);
    progress.Update(frame + 1);
  };
  callbacks.first_frame_mapped = [&stats] {
    stats.startup_s = SecondsSinceProcessStart();
    std::fprintf(stderr, "map_from_bag: first frame mapped after %.3f s\n", *stats.startup_s);
  };
  BagMappingResult read = MapBag(bag, topics, &session, callbacks);
  progress.Finish();
  if (instruction_spans) {
    instruction_spans->Finish();
    std::cerr << "map_from_bag: instruction counts of " << instruction_spans->dumped()
              << " spans dumped (" << instruction_spans->skipped() << " held no frame)\n";
  }
  stats.frames_read = read.frames_read;
  stats.lost = std::move(read.lost);
  stats.bag_begin_s = rosbag::View(bag).getBeginTime().toSec();
  if (!stats.lost.empty()) std::cerr << LostSpansLine(stats.lost, stats.bag_begin_s) << "\n";
  stats.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  stats.bag_span_s = (span_view.getEndTime() - span_view.getBeginTime()).toSec();

  const Mapper& mapper = *session.mapper();
  VectorMap map = mapper.ExportMap();
  map.metadata["bag"] = args.bag;
  map.metadata["config"] = args.config;
  map.metadata["extrinsic_source"] = stats.extrinsic_source;
  // Process start to the first frame mapped, s (null when none was).
  map.metadata["startup_s"] = stats.startup_s ? nlohmann::json(*stats.startup_s) : nullptr;
  // Messages of unreadable chunks and the spans of the bag they covered (docs/map_from_bag.md).
  map.metadata["lost"] = LostSpansToJson(stats.lost, stats.bag_begin_s);
  // A bag read past a missing index: what reading it in record order gave.
  if (stats.salvage) map.metadata["index"] = IndexLine(stats).substr(7);
  map.geo_origin = config.geo_origin;   // recorded in map.json; the GeoJSON needs it
  map.frame_id = config.ros.map_frame;  // the live nodelet's frame for the same config
  const BagRunPaths paths{args.bag, args.config,    args.classes,
                          args.out, args.stats_out, args.calibration_out};
  const std::string summary = BagRunSummary(paths, mapper, session.assembler(), map, stats);
  try {
    if (frame_stats) frame_stats->Close();
    if (publish_probe) publish_probe->Close();
    WriteOutputs(args.out, map, config.geo_origin, summary);
    if (!args.calibration_out.empty()) {
      Calibration calibration;
      calibration.T_base_cam = map.T_base_cam;
      calibration.covariance = map.T_base_cam_covariance;
      calibration.observed = map.T_base_cam_observed;
      calibration.base_frame = input.base_frame;
      if (!stats.camera_frame.empty()) calibration.camera_frame = stats.camera_frame;
      calibration.note = "from map_from_bag --bag " + args.bag + " --config " + args.config;
      const std::string error = WriteCalibrationFile(
          args.calibration_out, calibration, fs::absolute(args.config).lexically_normal().string());
      if (!error.empty()) throw std::runtime_error(error);
    }
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
