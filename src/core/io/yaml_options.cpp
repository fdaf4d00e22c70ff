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

// Scalars longer than this are cut in messages.
constexpr std::size_t kMaxQuotedChars = 40;

// The text of a map key; a non-scalar key (`? [a, b]: 1`) is an error naming `where`.
std::string KeyText(const YAML::Node& key, const std::string& where) {
  if (!key.IsScalar()) {
    throw OptionsError((where.empty() ? std::string("<root>") : where) + ": a key is " +
                       DescribeYamlNode(key) + ", expected a name");
  }
  return key.Scalar();
}

// Overlays `over` on `base`: maps merge key by key (recursively), anything else replaces.
YAML::Node Merge(const YAML::Node& base, const YAML::Node& over) {
  if (!base || !base.IsMap() || !over || !over.IsMap()) return YAML::Clone(over);
  YAML::Node merged = YAML::Clone(base);
  for (const auto& entry : over) {
    const std::string key = KeyText(entry.first, "");
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
  if (!root["base"].IsScalar()) {
    throw OptionsError(file_path + ": base: wrong type: expected a string, got " +
                       DescribeYamlNode(root["base"]));
  }
  std::string base_path = root["base"].Scalar();
  if (!base_path.empty() && base_path[0] != '/') {
    const std::size_t slash = file_path.find_last_of('/');
    if (slash != std::string::npos) base_path = file_path.substr(0, slash + 1) + base_path;
  }
  YAML::Node overrides = YAML::Clone(root);
  overrides.remove("base");
  const YAML::Node base = LoadWithBase(base_path, depth + 1);
  try {
    return Merge(base, overrides);
  } catch (const OptionsError& e) {
    throw OptionsError(file_path + ": " + e.what());
  }
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
    const std::string key = KeyText(entry.first, path_);
    if (std::find(used_.begin(), used_.end(), key) == used_.end()) {
      throw OptionsError(KeyPath(key) + ": unknown key");
    }
  }
}

std::string DescribeYamlNode(const YAML::Node& node) {
  if (!node || node.IsNull()) return "null";
  if (node.IsSequence()) return "a sequence";
  if (node.IsMap()) return "a map";
  const std::string& text = node.Scalar();
  return "the scalar '" +
         (text.size() > kMaxQuotedChars ? text.substr(0, kMaxQuotedChars) + "..." : text) + "'";
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
