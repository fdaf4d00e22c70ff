// The shipped mask class table (config/classes.yaml) and the mask values of its classes,
// for the tests that feed masks of every known class (test_absurd_masks,
// test_absurd_frames, the extraction tests).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "ipm_road_mapper/core/frontend/class_table.h"

namespace ipm_road_mapper {

// config/classes.yaml of the source tree.
inline ClassTable ShippedClasses() {
  return ClassTable::LoadFile(std::string(IRM_SOURCE_DIR) + "/config/classes.yaml");
}

// Every known (class, instance) value of `classes`, class by class, the first `n`.
inline std::vector<std::uint16_t> KnownValues(const ClassTable& classes, std::size_t n) {
  std::vector<std::uint16_t> values;
  for (const auto& [id, info] : classes.classes()) {
    for (int index = 0; index < kInstanceIdFactor && values.size() < n; ++index) {
      values.push_back(static_cast<std::uint16_t>(id * kInstanceIdFactor + index));
    }
  }
  return values;
}

}  // namespace ipm_road_mapper
