// The instance-mask class table (config/classes.yaml): class id -> name, kind and style.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "ipm_road_mapper/core/io/yaml_options.h"

namespace ipm_road_mapper {

// How a class is mapped (docs/design.md §1).
enum class ElementKind { kLane, kMarking };

// Lane line style, where known.
enum class LaneStyle { kUnknown, kSolid, kDashed };

const char* ToString(ElementKind kind);
const char* ToString(LaneStyle style);

// Default plausibility bounds on the ground (m) of a class that does not set its own: a
// lane line is at most this wide; a marking's rectangle at most this long and wide.
constexpr double kDefaultLaneMaxWidthM = 0.6;
constexpr double kDefaultMarkingMaxLengthM = 20.0;
constexpr double kDefaultMarkingMaxWidthM = 10.0;

// One class of the table.
struct ClassInfo {
  int id = 0;
  std::string name;
  ElementKind kind = ElementKind::kMarking;
  LaneStyle style = LaneStyle::kUnknown;
  // Largest plausible size on the ground (m): a lane line's width; a marking's rectangle's
  // longer side (max_length_m) and shorter side (max_width_m). Set from the kind's default.
  double max_width_m = kDefaultMarkingMaxWidthM;
  double max_length_m = kDefaultMarkingMaxLengthM;  // markings only
};

// Pixel value encoding of the 16UC1 instance masks.
constexpr int kInstanceIdFactor = 1000;
constexpr int kMaxClassId = 65;  // 65 * 1000 + 535 is the largest 16-bit value

// Class id of a mask pixel value (0 for background, value < 1000).
inline int ClassIdOf(unsigned value) { return static_cast<int>(value) / kInstanceIdFactor; }

// The validated class table.
class ClassTable {
 public:
  // Loads `classes:` from YAML. Throws OptionsError naming the offending entry: a
  // duplicate id or name, an unknown kind or style, an id out of 1..kMaxClassId, a size
  // bound not > 0, max_length_m on a lane or a marking's max_width_m above its max_length_m.
  static ClassTable Load(OptionsReader reader);
  static ClassTable LoadFile(const std::string& path);

  // The class with this id, or nullptr.
  const ClassInfo* Find(int class_id) const;
  // The class with this name, or nullptr.
  const ClassInfo* FindByName(const std::string& name) const;

  const std::map<int, ClassInfo>& classes() const { return classes_; }

 private:
  std::map<int, ClassInfo> classes_;
};

}  // namespace ipm_road_mapper
