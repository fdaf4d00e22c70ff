#include "ipm_road_mapper/core/frontend/class_table.h"

#include <algorithm>
#include <optional>
#include <string>

namespace ipm_road_mapper {

const char* ToString(ElementKind kind) { return kind == ElementKind::kLane ? "lane" : "marking"; }

const char* ToString(LaneStyle style) {
  switch (style) {
    case LaneStyle::kSolid:
      return "solid";
    case LaneStyle::kDashed:
      return "dashed";
    default:
      return "unknown";
  }
}

ClassTable ClassTable::Load(OptionsReader reader) {
  ClassTable table;
  const YAML::Node list = reader.Raw("classes");
  reader.RejectUnknownKeys();
  if (!list || !list.IsSequence() || list.size() == 0) {
    throw OptionsError("classes: must be a non-empty list");
  }
  for (std::size_t i = 0; i < list.size(); ++i) {
    OptionsReader entry(list[i], "classes[" + std::to_string(i) + "]");
    ClassInfo info;
    std::string kind, style = "unknown";
    entry.ReadRequired<int>("id", &info.id, [](const int& id) -> std::string {
      return id >= 1 && id <= kMaxClassId ? "" : "must be in 1.." + std::to_string(kMaxClassId);
    });
    entry.ReadRequired<std::string>("name", &info.name);
    entry.ReadRequired<std::string>("kind", &kind);
    entry.Read<std::string>("style", &style);
    std::optional<double> max_width_m, max_length_m;
    if (entry.Has("max_width_m")) {
      max_width_m = 0.0;
      entry.Read<double>("max_width_m", &*max_width_m, CheckPositive);
    }
    if (entry.Has("max_length_m")) {
      max_length_m = 0.0;
      entry.Read<double>("max_length_m", &*max_length_m, CheckPositive);
    }
    entry.RejectUnknownKeys();
    const std::string where =
        entry.path() + " (id " + std::to_string(info.id) + ", " + info.name + ")";
    if (kind == "lane") {
      info.kind = ElementKind::kLane;
    } else if (kind == "marking") {
      info.kind = ElementKind::kMarking;
    } else {
      throw OptionsError(where + ": unknown kind '" + kind + "' (lane or marking)");
    }
    if (info.kind == ElementKind::kLane) {
      if (max_length_m) throw OptionsError(where + ": max_length_m is for markings, not lanes");
      info.max_width_m = max_width_m.value_or(kDefaultLaneMaxWidthM);
    } else {
      info.max_length_m = max_length_m.value_or(kDefaultMarkingMaxLengthM);
      info.max_width_m =
          max_width_m.value_or(std::min(kDefaultMarkingMaxWidthM, info.max_length_m));
      if (info.max_width_m > info.max_length_m) {
        throw OptionsError(where + ": max_width_m must be <= max_length_m");
      }
    }
    if (style == "solid") {
      info.style = LaneStyle::kSolid;
    } else if (style == "dashed") {
      info.style = LaneStyle::kDashed;
    } else if (style != "unknown") {
      throw OptionsError(where + ": unknown style '" + style + "' (solid, dashed or unknown)");
    }
    if (table.classes_.count(info.id)) throw OptionsError(where + ": duplicate id");
    if (table.FindByName(info.name)) throw OptionsError(where + ": duplicate name");
    table.classes_[info.id] = info;
  }
  return table;
}

ClassTable ClassTable::LoadFile(const std::string& path) {
  try {
    return Load(OptionsReader::FromFile(path));
  } catch (const OptionsError& e) {
    throw OptionsError(path + ": " + e.what());
  }
}

const ClassInfo* ClassTable::Find(int class_id) const {
  const auto it = classes_.find(class_id);
  return it == classes_.end() ? nullptr : &it->second;
}

const ClassInfo* ClassTable::FindByName(const std::string& name) const {
  for (const auto& [id, info] : classes_) {
    if (info.name == name) return &info;
  }
  return nullptr;
}

}  // namespace ipm_road_mapper
