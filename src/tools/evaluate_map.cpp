// evaluate_map: measures an exported map against the ground truth of a drive, prints a
// table and writes the metrics JSON (keys in docs/file_formats.md).
//
//   rosrun ipm_road_mapper evaluate_map --map map.json --ground-truth ground_truth.json
//       [--json metrics.json] [--map-bytes N] [--view-range-m M]
//
// Exit codes: 0 success (or --help), 2 bad input (bad command line, missing or malformed
// file; one line on stderr), 1 any other failure (e.g. the metrics file cannot be written).
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>

#include "ipm_road_mapper/core/io/ground_truth.h"
#include "ipm_road_mapper/core/map/vector_map.h"
#include "ipm_road_mapper/eval/evaluation.h"
#include "ipm_road_mapper/pipeline/command_line.h"

namespace {

struct Arguments {
  std::string map_path;
  std::string ground_truth_path;
  std::string json_path;        // empty: no JSON file
  std::int64_t map_bytes = -1;  // < 0: the map file's size
  std::int64_t view_range_m =
      static_cast<std::int64_t>(ipm_road_mapper::EvaluationOptions().view_range_m);
};

// Parses the command line (pipeline/command_line.h): the exit code when the tool stops
// there (--help: 0, a bad command line: 2), else nullopt with *args filled in.
std::optional<int> ParseArguments(int argc, char** argv, Arguments* args) {
  ipm_road_mapper::CommandLine line(
      "evaluate_map",
      "Measures an exported map against the ground truth of a drive, prints a table and "
      "writes the metrics JSON (docs/file_formats.md).");
  line.Required("map", "<map.json>", &args->map_path, "the map (map_from_bag's map.json)")
      .Required("ground-truth", "<ground_truth.json>", &args->ground_truth_path,
                "the drive's ground truth (generate_drive)")
      .Optional("json", "<metrics.json>", &args->json_path, "none", "metrics JSON to write")
      .Integer("map-bytes", "<n>", &args->map_bytes, 0, std::numeric_limits<std::int64_t>::max(),
               false, "the size of the --map file", "map size for the storage metrics")
      .Integer("view-range-m", "<m>", &args->view_range_m, 1, 100000, false,
               std::to_string(args->view_range_m) + " (config/mapper.yaml's ipm.max_range_m)",
               "ground farther from base_link is out of view for the view's ceiling "
               "(eval/view_ceiling.h)");
  return line.ParseOrExitCode(argc, argv);
}

int Run(int argc, char** argv) {
  using namespace ipm_road_mapper;
  Arguments args;
  if (const std::optional<int> exit_code = ParseArguments(argc, argv, &args)) return *exit_code;
  const VectorMap map = LoadVectorMapJson(args.map_path);
  const GroundTruth gt = LoadGroundTruthJson(args.ground_truth_path);

  EvaluationOptions options;
  options.map_bytes = args.map_bytes >= 0
                          ? args.map_bytes
                          : static_cast<std::int64_t>(std::filesystem::file_size(args.map_path));
  options.view_range_m = static_cast<double>(args.view_range_m);
  const Metrics metrics = EvaluateMap(map, gt, options);
  std::cout << "map: " << args.map_path << "\nground truth: " << args.ground_truth_path
            << " (scenario '" << gt.scenario << "', seed " << gt.seed << ")\n"
            << FormatMetricsTable(metrics);
  if (!args.json_path.empty()) {
    std::ofstream out(args.json_path);
    out << MetricsToJson(metrics).dump(2) << "\n";
    out.close();
    if (!out) {
      std::cerr << "evaluate_map: error: cannot write " << args.json_path << ": "
                << std::strerror(errno) << "\n";
      return 1;
    }
    std::cout << "\nmetrics written to " << args.json_path << "\n";
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return Run(argc, argv);
  } catch (const ipm_road_mapper::MapFormatError& e) {
    std::cerr << "evaluate_map: error: " << e.what() << "\n";
  } catch (const std::exception& e) {
    std::cerr << "evaluate_map: error: " << e.what() << "\n";
    return 1;
  }
  return 2;
}
