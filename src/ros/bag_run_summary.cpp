#include "ipm_road_mapper/ros/bag_run_summary.h"

#include <cstdio>
#include <sstream>

#include "ipm_road_mapper/pipeline/mapper_summary.h"

namespace ipm_road_mapper {

std::string IndexLine(const BagRunStats& stats) {
  if (!stats.salvage) return "index: ok";
  const BagSalvage& s = *stats.salvage;
  std::ostringstream line;
  line.setf(std::ios::fixed);
  line.precision(2);
  line << "index: missing (" << stats.index_problem << "): read in record order, " << s.messages
       << " messages in " << s.chunks << " chunks (" << s.bad_chunks
       << " chunks did not decompress), record times " << s.first_stamp - stats.bag_begin_s
       << " to " << s.last_stamp - stats.bag_begin_s << " s; " << s.end
       << "; whatever was recorded after that is lost";
  return line.str();
}

std::string StartupText(const std::optional<double>& startup_s) {
  if (!startup_s) return "none";
  char text[32];
  std::snprintf(text, sizeof(text), "%.3f", *startup_s);
  return text;
}

std::string BagRunSummary(const BagRunPaths& paths, const Mapper& mapper,
                          const FrameAssembler& assembler, const VectorMap& map,
                          const BagRunStats& stats) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(2);
  s << "bag: " << paths.bag << "\nconfig: " << paths.config << " (method "
    << mapper.options().method << ")\nclasses: " << paths.classes
    << "\nextrinsic: " << stats.extrinsic_source << "\n"
    << "frames read: " << stats.frames_read << "\n"
    << MapperSummaryLines(mapper, assembler, map) << "startup_s: " << StartupText(stats.startup_s)
    << " (process start to the first frame mapped)\n"
    << IndexLine(stats) << "\n"
    << "lost: " << stats.lost.messages << " messages (" << stats.lost.masks << " masks) in "
    << stats.lost.spans.size()
    << " unreadable spans: " << FormatLostSpans(stats.lost, stats.bag_begin_s)
    << (stats.lost.empty() ? "" : " (first error: " + stats.lost.first_error + ")") << "\n"
    << "wall time: " << stats.wall_s << " s; "
    << (stats.wall_s > 0 ? stats.frames_read / stats.wall_s : 0.0) << " frames/s; bag span "
    << stats.bag_span_s << " s; real-time factor "
    << (stats.wall_s > 0 ? stats.bag_span_s / stats.wall_s : 0.0) << "x\n"
    << "outputs: " << paths.out << "/{map.json, "
    << (map.geo_origin ? "map.geojson, map.osm, " : "") << "map_trajectory_tum.txt, summary.txt}"
    << (paths.stats_out.empty() ? "" : ", " + paths.stats_out)
    << (paths.calibration_out.empty() ? "" : ", " + paths.calibration_out) << "\n";
  return s.str();
}

}  // namespace ipm_road_mapper
