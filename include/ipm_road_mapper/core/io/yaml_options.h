// Typed, validated reading of YAML option trees, shared by every options struct of the
// package (mapper config, scenarios, class table). Unknown keys and bad values are errors
// that name the offending key path, e.g. "ipm.max_range_m: must be > 0 (got -3)".
#pragma once

#include <yaml-cpp/yaml.h>

#include <functional>
#include <initializer_list>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace ipm_road_mapper {

// Makes T non-deducible in a parameter, so `Read("k", &d, CheckPositive)` deduces T from &d.
template <typename T>
struct NonDeduced {
  using type = T;
};

// Validates a value: empty string when valid, else the reason.
template <typename T>
using OptionCheck = std::function<std::string(const typename NonDeduced<T>::type&)>;

// What an option of type T must be, for wrong-type messages ("a number", "true or false").
template <typename T>
const char* ExpectedTypeName() {
  if constexpr (std::is_same_v<T, bool>) {
    return "true or false";
  } else if constexpr (std::is_integral_v<T>) {
    return "an integer";
  } else if constexpr (std::is_floating_point_v<T>) {
    return "a number";
  } else if constexpr (std::is_same_v<T, std::string>) {
    return "a string";
  } else if constexpr (std::is_same_v<T, std::vector<double>>) {
    return "a sequence of numbers";
  } else if constexpr (std::is_same_v<T, std::vector<int>>) {
    return "a sequence of integers";
  } else if constexpr (std::is_same_v<T, std::vector<std::string>>) {
    return "a sequence of strings";
  } else {
    return "a value of another type";
  }
}

// What a YAML node is, for messages: "the scalar 'abc'", "a sequence", "a map", "null".
std::string DescribeYamlNode(const YAML::Node& node);

// Thrown for any invalid option; what() is one line naming the key path.
class OptionsError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A view of one YAML map that records which keys were read, so that unknown keys can be
// reported (a typo must never be silently ignored).
class OptionsReader {
 public:
  // `path` prefixes error messages ("" for the root).
  OptionsReader(YAML::Node node, std::string path);

  // Loads a YAML file; throws OptionsError when it is missing or malformed. A top-level
  // `base: <path>` (relative to the file) loads that file first and overlays this one on
  // it, map by map, so a variant config states only what differs.
  static OptionsReader FromFile(const std::string& file_path);

  bool Has(const std::string& key) const;

  // Reads `key` into *value when present (otherwise *value keeps its default). `check`
  // returns an empty string when the value is valid, else the reason.
  template <typename T>
  void Read(const std::string& key, T* value, const OptionCheck<T>& check = nullptr) {
    used_.push_back(key);
    if (!node_[key]) return;
    try {
      *value = node_[key].as<T>();
    } catch (const YAML::Exception&) {
      // yaml-cpp's own message ("bad conversion") names neither the key nor the types.
      throw OptionsError(KeyPath(key) + ": wrong type: expected " + ExpectedTypeName<T>() +
                         ", got " + DescribeYamlNode(node_[key]));
    }
    if (check) {
      const std::string reason = check(*value);
      if (!reason.empty()) throw OptionsError(KeyPath(key) + ": " + reason);
    }
  }

  // Like Read, but the key must be present.
  template <typename T>
  void ReadRequired(const std::string& key, T* value, const OptionCheck<T>& check = nullptr) {
    if (!Has(key)) throw OptionsError(KeyPath(key) + ": required key is missing");
    Read<T>(key, value, check);
  }

  // The sub-map at `key` (an empty map when absent; an error when not a map).
  OptionsReader Child(const std::string& key);

  // The raw node at `key` (marks it used), for sequences of maps.
  YAML::Node Raw(const std::string& key);

  // Throws when the map has a key that no Read/Child/Raw asked for.
  void RejectUnknownKeys() const;

  const std::string& path() const { return path_; }
  std::string KeyPath(const std::string& key) const;

 private:
  YAML::Node node_;
  std::string path_;
  std::vector<std::string> used_;
};

// Common checks for Read's `check` argument.
std::string CheckPositive(const double& v);
std::string CheckNonNegative(const double& v);
std::string CheckPositiveInt(const int& v);
std::string CheckProbability(const double& v);

}  // namespace ipm_road_mapper
