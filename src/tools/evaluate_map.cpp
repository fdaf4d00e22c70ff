// evaluate_map: measures an exported map against the ground truth of a drive, prints a
// table and writes the metrics JSON (keys in docs/file_formats.md).
//
//   rosrun ipm_road_mapper evaluate_map --map map.json --ground-truth ground_truth.json
//       [--json metrics.json] [--map-bytes N]
//
// Exit codes: 0 success, 2 bad input (usage, missing or malformed file; one line on stderr),
// 1 any other failure (e.g. the metrics file cannot be written).
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>

#include "ipm_road_mapper/eval/evaluation.h"
#include "ipm_road_mapper/core/io/ground_truth.h"
#include "ipm_road_mapper/core/map/vector_map.h"

namespace {

constexpr char kUsage[] =
    "usage: evaluate_map --map <map.json> --ground-truth <ground_truth.json> "
    "[--json <metrics.json>] [--map-bytes <n>]";

// A bad command line or input file: reported in one line, exit code 2.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct Arguments {
  std::string map_path;
  std::string ground_truth_path;
  std::string json_path;  // empty: no JSON file
  std::optional<std::int64_t> map_bytes;
  bool help = false;
};

std::int64_t ParseByteCount(const std::string& text) {
  std::size_t used = 0;
  long long value = -1;
  try {
    value = std::stoll(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || value < 0) {
    throw InputError("--map-bytes needs a non-negative integer, got '" + text + "'");
  }
  return value;
}

// Accepts "--key value" and "--key=value".
Arguments ParseArguments(int argc, char** argv) {
  Arguments args;
  std::map<std::string, std::string> values;
  for (int i = 1; i < argc; ++i) {
    std::string key = argv[i];
    if (key == "-h" || key == "--help") {
      args.help = true;
      return args;
    }
    std::string value;
    const std::size_t equals = key.find('=');
    const bool inline_value = equals != std::string::npos;
    if (inline_value) {
      value = key.substr(equals + 1);
      key = key.substr(0, equals);
    }
    if (key != "--map" && key != "--ground-truth" && key != "--json" && key != "--map-bytes") {
      throw InputError("unknown option '" + key + "'");
    }
    if (!inline_value) {
      if (i + 1 >= argc) throw InputError("option " + key + " needs a value");
      value = argv[++i];
    }
    if (!values.emplace(key, value).second) throw InputError("option " + key + " given twice");
  }
  if (!values.count("--map")) throw InputError("--map is required");
  if (!values.count("--ground-truth")) throw InputError("--ground-truth is required");
  args.map_path = values["--map"];
  args.ground_truth_path = values["--ground-truth"];
  if (values.count("--json")) args.json_path = values["--json"];
  if (values.count("--map-bytes")) args.map_bytes = ParseByteCount(values["--map-bytes"]);
  return args;
}

int Run(int argc, char** argv) {
  using namespace ipm_road_mapper;
  const Arguments args = ParseArguments(argc, argv);
  if (args.help) {
    std::cout << kUsage << "\n";
    return 0;
  }
  const VectorMap map = LoadVectorMapJson(args.map_path);
  const GroundTruth gt = LoadGroundTruthJson(args.ground_truth_path);

  EvaluationOptions options;
  options.map_bytes = args.map_bytes
                          ? *args.map_bytes
                          : static_cast<std::int64_t>(std::filesystem::file_size(args.map_path));
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
  } catch (const InputError& e) {
    std::cerr << "evaluate_map: error: " << e.what() << " (" << kUsage << ")\n";
  } catch (const ipm_road_mapper::MapFormatError& e) {
    std::cerr << "evaluate_map: error: " << e.what() << "\n";
  } catch (const std::exception& e) {
    std::cerr << "evaluate_map: error: " << e.what() << "\n";
    return 1;
  }
  return 2;
}
