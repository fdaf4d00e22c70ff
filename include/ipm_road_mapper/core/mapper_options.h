// Typed options of the mapper, loaded and validated in one place from YAML (the offline
// runner reads config/mapper.yaml directly; the nodelet converts its private parameters
// to the same YAML tree), so both share one schema. Angles are degrees in the file
// (`*_deg` keys) and radians here.
#pragma once

#include <string>

#include "ipm_road_mapper/core/ipm_uncertainty.h"
#include "ipm_road_mapper/core/yaml_options.h"

namespace ipm_road_mapper {

// IPM and its error model.
struct IpmOptions {
  double max_range_m = 40.0;  // ground points farther than this are rejected
  IpmErrorModel error_model;  // Omega_p inputs (DESIGN.md defaults)
};

// Everything the mapper is configured with.
struct MapperOptions {
  IpmOptions ipm;
};

// Reads the `ipm` section; throws OptionsError naming the bad key.
IpmOptions LoadIpmOptions(OptionsReader reader);

// Reads a whole mapper config; unknown keys are errors. Throws OptionsError.
MapperOptions LoadMapperOptions(OptionsReader reader);

// A multi-line, human-readable dump of the options (printed at start-up).
std::string ToString(const MapperOptions& options);

}  // namespace ipm_road_mapper
