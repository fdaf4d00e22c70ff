// The mapper's part of a run's summary (map_from_bag's summary.txt, docs/map_from_bag.md):
// what the frames, the odometry, the extraction and the map came to, and one line each about
// the optimizer, the refined extrinsic as a calibration and the front end's time. No ROS.
#pragma once

#include <string>

#include "ipm_road_mapper/core/map/vector_map.h"
#include "ipm_road_mapper/core/mapper/mapper.h"
#include "ipm_road_mapper/pipeline/frame_assembler.h"

namespace ipm_road_mapper {

// The lines from "frames used:" to the front end's, each ending in a newline; `map` is the
// exported map the counts are of.
std::string MapperSummaryLines(const Mapper& mapper, const FrameAssembler& assembler,
                               const VectorMap& map);

// One line about the optimizer: windows, solve time, how far the extrinsic moved.
std::string BackendLine(const Mapper& mapper);

// One line about the refined extrinsic as a calibration: its 1-sigma per axis, the axes the
// data observed and how many refined extrinsics the guard refused.
std::string CalibrationLine(const Mapper& mapper);

// One line about the front end's time per frame (the caller's thread).
std::string FrontEndLine(const Mapper& mapper);

}  // namespace ipm_road_mapper
