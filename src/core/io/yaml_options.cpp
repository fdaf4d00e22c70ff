#include "ipm_road_mapper/core/io/yaml_options.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace ipm_road_mapper {

OptionsReader::OptionsReader(YAML::Node node, std::string path)
    : node_(std::move(node)), path_(std::move(path)) {
  if (node_ && !node_.IsNull() && !node_.IsMap()) {
    throw OptionsError((path_.empty() ? std::string("<root>") : path_) + ": must be a map");
  }
}

namespace {

// Overlays `over` on `base`: maps merge key by key (recursively), anything else replaces.
YAML::Node Merge(const YAML::Node& base, const YAML::Node& over) {
  if (!base || !base.IsMap() || !over || !over.IsMap()) return YAML::Clone(over);
  YAML::Node merged = YAML::Clone(base);
  for (const auto& entry : over) {
    const std::string key = entry.first.as<std::string>();
    merged[key] = Merge(base[key], entry.second);
  }
  return merged;
}

YAML::Node LoadWithBase(const std::string& file_path, int depth) {
  if (depth > 8) throw OptionsError(file_path + ": `base` chain too deep (a cycle?)");
  YAML::Node root;
  try {
    root = YAML::LoadFile(file_path);
  } catch (const YAML::BadFile&) {
    throw OptionsError(file_path + ": cannot open file");
  } catch (const YAML::Exception& e) {
    throw OptionsError(file_path + ": malformed YAML: " + e.what());
  }
  if (!root.IsMap() || !root["base"]) return root;
  std::string base_path = root["base"].as<std::string>();
  if (!base_path.empty() && base_path[0] != '/') {
    const std::size_t slash = file_path.find_last_of('/');
    if (slash != std::string::npos) base_path = file_path.substr(0, slash + 1) + base_path;
  }
  YAML::Node overrides = YAML::Clone(root);
  overrides.remove("base");
  return Merge(LoadWithBase(base_path, depth + 1), overrides);
}

}  // namespace

OptionsReader OptionsReader::FromFile(const std::string& file_path) {
  return OptionsReader(LoadWithBase(file_path, 0), "");
}

bool OptionsReader::Has(const std::string& key) const {
  return node_ && node_.IsMap() && static_cast<bool>(node_[key]);
}

OptionsReader OptionsReader::Child(const std::string& key) {
  used_.push_back(key);
  YAML::Node child = Has(key) ? node_[key] : YAML::Node(YAML::NodeType::Map);
  return OptionsReader(child, KeyPath(key));
}

YAML::Node OptionsReader::Raw(const std::string& key) {
  used_.push_back(key);
  return Has(key) ? node_[key] : YAML::Node();
}

void OptionsReader::RejectUnknownKeys() const {
  if (!node_ || !node_.IsMap()) return;
  for (const auto& entry : node_) {
    const std::string key = entry.first.as<std::string>();
    if (std::find(used_.begin(), used_.end(), key) == used_.end()) {
      throw OptionsError(KeyPath(key) + ": unknown key");
    }
  }
}

std::string OptionsReader::KeyPath(const std::string& key) const {
  return path_.empty() ? key : path_ + "." + key;
}

namespace {
template <typename T>
std::string Got(const T& v) {
  std::ostringstream s;
  s << " (got " << v << ")";
  return s.str();
}
}  // namespace

std::string CheckPositive(const double& v) {
  return std::isfinite(v) && v > 0.0 ? "" : "must be > 0" + Got(v);
}
std::string CheckNonNegative(const double& v) {
  return std::isfinite(v) && v >= 0.0 ? "" : "must be >= 0" + Got(v);
}
std::string CheckPositiveInt(const int& v) { return v > 0 ? "" : "must be > 0" + Got(v); }
std::string CheckProbability(const double& v) {
  return std::isfinite(v) && v >= 0.0 && v <= 1.0 ? "" : "must be in [0, 1]" + Got(v);
}

}  // namespace ipm_road_mapper
