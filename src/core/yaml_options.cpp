#include "ipm_road_mapper/core/yaml_options.h"

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

OptionsReader OptionsReader::FromFile(const std::string& file_path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(file_path);
  } catch (const YAML::BadFile&) {
    throw OptionsError(file_path + ": cannot open file");
  } catch (const YAML::Exception& e) {
    throw OptionsError(file_path + ": malformed YAML: " + e.what());
  }
  return OptionsReader(root, "");
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
