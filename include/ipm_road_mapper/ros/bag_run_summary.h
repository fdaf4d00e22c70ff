// map_from_bag's summary.txt (docs/map_from_bag.md): the run's inputs, the mapper's lines
// (pipeline/mapper_summary.h), the start-up time, how the bag was read (its index, the
// spans lost to unreadable chunks), the wall time and the outputs.
#pragma once

#include <cstddef>
#include <optional>
#include <string>

#include "ipm_road_mapper/core/map/vector_map.h"
#include "ipm_road_mapper/core/mapper/mapper.h"
#include "ipm_road_mapper/pipeline/frame_assembler.h"
#include "ipm_road_mapper/ros/bag_read_loss.h"
#include "ipm_road_mapper/ros/unindexed_bag.h"

namespace ipm_road_mapper {

// What the run was given: its bag, config and class table, and where its outputs go
// (stats_out and calibration_out empty when not asked for).
struct BagRunPaths {
  std::string bag, config, classes, out, stats_out, calibration_out;
};

// What the run did.
struct BagRunStats {
  std::size_t frames_read = 0;
  double bag_span_s = 0.0;
  double wall_s = 0.0;
  std::optional<double> startup_s;  // process start to the first frame mapped
  std::string extrinsic_source;
  std::string camera_frame;           // the masks' frame (empty when the config gave the extrinsic)
  BagReadLoss lost;                   // what could not be read (corrupt chunks)
  double bag_begin_s = 0.0;           // the bag's first record time; lost spans are relative to it
  std::string index_problem;          // why the bag had to be read past its index ("" = not)
  std::optional<BagSalvage> salvage;  // what reading it in record order gave
};

// The summary line about the bag's index: "index: ok", or how the bag was read past a
// missing one ("index: missing (...): ...").
std::string IndexLine(const BagRunStats& stats);

// Seconds with 3 decimals, or "none" when no frame was mapped.
std::string StartupText(const std::optional<double>& startup_s);

// The whole summary.txt; `map` is the exported map.
std::string BagRunSummary(const BagRunPaths& paths, const Mapper& mapper,
                          const FrameAssembler& assembler, const VectorMap& map,
                          const BagRunStats& stats);

}  // namespace ipm_road_mapper
