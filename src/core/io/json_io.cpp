#include "json_io.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <vector>

#include "ipm_road_mapper/core/io/json_limits.h"
#include "ipm_road_mapper/core/map/vector_map.h"

namespace ipm_road_mapper {
namespace json_io {
namespace {

// Quaternions further than this from unit norm are rejected rather than normalized.
constexpr double kQuaternionNormTolerance = 1e-3;

// "null" for NaN/inf (how nlohmann stores them), otherwise the JSON type name.
std::string Describe(const nlohmann::json& j) {
  if (j.is_null()) return "null (NaN, infinity or missing value)";
  return std::string("a ") + j.type_name();
}

std::string ErrnoText() { return std::strerror(errno); }

// A number as %g prints it ("1e+08"), for messages.
std::string ShortNumber(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%g", value);
  return text;
}

}  // namespace

void Fail(const std::string& where, const std::string& what) {
  throw MapFormatError(where.empty() ? what : where + ": " + what);
}

std::string Key(const std::string& where, const char* key) {
  return where.empty() ? std::string(key) : where + "." + key;
}

std::string Index(const std::string& where, std::size_t index) {
  return where + "[" + std::to_string(index) + "]";
}

const nlohmann::json& Member(const nlohmann::json& j, const char* key, const std::string& where) {
  if (!j.is_object()) Fail(where, "expected an object, got " + Describe(j));
  const auto it = j.find(key);
  if (it == j.end()) Fail(Key(where, key), "missing");
  return *it;
}

double ReadNumber(const nlohmann::json& j, const std::string& where) {
  if (!j.is_number()) Fail(where, "expected a finite number, got " + Describe(j));
  const double value = j.get<double>();
  if (!std::isfinite(value)) Fail(where, "not a finite number");
  return value;
}

int ReadInt(const nlohmann::json& j, const std::string& where) {
  if (!j.is_number_integer()) Fail(where, "expected an integer, got " + Describe(j));
  if (j.is_number_unsigned()) {
    const auto value = j.get<std::uint64_t>();
    if (value > static_cast<std::uint64_t>(std::numeric_limits<int>::max())) {
      Fail(where, "integer out of range");
    }
    return static_cast<int>(value);
  }
  const auto value = j.get<std::int64_t>();
  if (value < std::numeric_limits<int>::min() || value > std::numeric_limits<int>::max()) {
    Fail(where, "integer out of range");
  }
  return static_cast<int>(value);
}

std::uint64_t ReadUint64(const nlohmann::json& j, const std::string& where) {
  if (j.is_number_unsigned()) return j.get<std::uint64_t>();
  if (j.is_number_integer()) Fail(where, "expected a non-negative integer");
  Fail(where, "expected a non-negative integer, got " + Describe(j));
}

std::string ReadString(const nlohmann::json& j, const std::string& where) {
  if (!j.is_string()) Fail(where, "expected a string, got " + Describe(j));
  return j.get<std::string>();
}

const nlohmann::json& ReadArray(const nlohmann::json& j, const std::string& where,
                                std::size_t max_size) {
  if (!j.is_array()) Fail(where, "expected an array, got " + Describe(j));
  if (j.size() > max_size) {
    Fail(where, std::to_string(j.size()) + " elements, more than the " + std::to_string(max_size) +
                    " allowed");
  }
  return j;
}

Eigen::Vector3d ReadVector3(const nlohmann::json& j, const std::string& where) {
  if (!j.is_array() || j.size() != 3) Fail(where, "expected [x, y, z]");
  const Eigen::Vector3d v(ReadNumber(j[0], Index(where, 0)), ReadNumber(j[1], Index(where, 1)),
                          ReadNumber(j[2], Index(where, 2)));
  const double distance_m = v.stableNorm();  // no overflow for 1e300
  static_assert(json_limits::kMaxCoordinateM == 1e7, "update the message below");
  if (!(distance_m <= json_limits::kMaxCoordinateM)) {
    Fail(where, "coordinate " + ShortNumber(distance_m) + " m beyond the 1e7 m bound");
  }
  return v;
}

Eigen::Isometry3d ReadPose(const nlohmann::json& j, const std::string& where) {
  if (!j.is_object()) Fail(where, "expected a pose {\"t\": [...], \"q_xyzw\": [...]}");
  const Eigen::Vector3d t = ReadVector3(Member(j, "t", where), Key(where, "t"));
  const std::string q_where = Key(where, "q_xyzw");
  const nlohmann::json& q_json = Member(j, "q_xyzw", where);
  if (!q_json.is_array() || q_json.size() != 4) Fail(q_where, "expected [qx, qy, qz, qw]");
  const Eigen::Quaterniond q(ReadNumber(q_json[3], Index(q_where, 3)),   // w
                             ReadNumber(q_json[0], Index(q_where, 0)),   // x
                             ReadNumber(q_json[1], Index(q_where, 1)),   // y
                             ReadNumber(q_json[2], Index(q_where, 2)));  // z
  if (std::abs(q.norm() - 1.0) > kQuaternionNormTolerance) {
    Fail(q_where, "not a unit quaternion (norm " + std::to_string(q.norm()) + ")");
  }
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = q.normalized().toRotationMatrix();
  T.translation() = t;
  return T;
}

double OptionalNumber(const nlohmann::json& j, const char* key, double fallback,
                      const std::string& where) {
  return j.contains(key) ? ReadNumber(j[key], Key(where, key)) : fallback;
}

int OptionalInt(const nlohmann::json& j, const char* key, int fallback, const std::string& where) {
  return j.contains(key) ? ReadInt(j[key], Key(where, key)) : fallback;
}

std::string OptionalString(const nlohmann::json& j, const char* key, const std::string& fallback,
                           const std::string& where) {
  return j.contains(key) ? ReadString(j[key], Key(where, key)) : fallback;
}

void CheckDepth(const nlohmann::json& j, int max_depth, const std::string& where) {
  std::vector<std::pair<const nlohmann::json*, int>> pending{{&j, 1}};
  while (!pending.empty()) {
    const auto [node, depth] = pending.back();
    pending.pop_back();
    if (!node->is_structured()) continue;
    if (depth > max_depth) {
      Fail(where, "nesting deeper than " + std::to_string(max_depth) + " levels");
    }
    for (const nlohmann::json& child : *node) pending.emplace_back(&child, depth + 1);
  }
}

void CheckFormatHeader(const nlohmann::json& root, const char* format, int version) {
  if (!root.is_object()) Fail("", "the document is not a JSON object");
  const std::string found_format = ReadString(Member(root, "format", ""), "format");
  if (found_format != format) {
    Fail("format", "expected \"" + std::string(format) + "\", got \"" + found_format + "\"");
  }
  const int found_version = ReadInt(Member(root, "version", ""), "version");
  if (found_version != version) {
    Fail("version", "unsupported version " + std::to_string(found_version) +
                        " (this build reads version " + std::to_string(version) + ")");
  }
}

double RoundToDecimals(double value, int decimals) {
  if (decimals < 0) return value;
  const double scale = std::pow(10.0, decimals);  // exact for decimals <= 22
  // Beyond 2^53 every double is an integer: the value has no digits that fine to round.
  if (!(std::abs(value) * scale < 9007199254740992.0)) return value + 0.0;
  return std::round(value * scale) / scale + 0.0;  // + 0.0 turns -0 into +0
}

nlohmann::json Vector3ToJson(const Eigen::Vector3d& v, int decimals) {
  return nlohmann::json::array({RoundToDecimals(v.x(), decimals), RoundToDecimals(v.y(), decimals),
                                RoundToDecimals(v.z(), decimals)});
}

nlohmann::json ParseJsonFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw MapFormatError(path + ": cannot open file: " + ErrnoText());
  const std::streamoff size = in.tellg();
  if (size < 0) throw MapFormatError(path + ": cannot read file: " + ErrnoText());
  if (static_cast<std::uintmax_t>(size) > json_limits::kMaxFileBytes) {
    throw MapFormatError(path + ": " + std::to_string(size) + " bytes, more than the " +
                         std::to_string(json_limits::kMaxFileBytes) + " allowed");
  }
  in.seekg(0);
  std::string text(static_cast<std::size_t>(size), '\0');
  if (!in.read(text.data(), size)) throw MapFormatError(path + ": read error");
  // Depth and sizes first, on the raw text: nlohmann builds (and copies) documents
  // recursively, so a deeply nested file must never reach it.
  const std::string problem = json_limits::ScanJsonText(text);
  if (!problem.empty()) throw MapFormatError(path + ": " + problem);
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    // e.what() is "[json.exception.parse_error.101] parse error at line 3, ...": one line.
    // Numbers beyond the double range (1e999) come as out_of_range.406.
    std::string message = e.what();
    const std::size_t tag_end = message.find("] ");
    if (tag_end != std::string::npos) message = message.substr(tag_end + 2);
    throw MapFormatError(path + ": not valid JSON (" + message + ")");
  }
}

void WriteFileAtomically(const std::string& path, const std::string& contents) {
  const std::size_t slash = path.rfind('/');
  const std::string folder = slash == std::string::npos ? "." : path.substr(0, slash + 1);
  const std::string base = slash == std::string::npos ? path : path.substr(slash + 1);
  if (base.empty()) throw std::runtime_error(path + ": not a file name");
  std::string temp_path = folder + (folder == "." ? "/." : ".") + base + ".tmp.XXXXXX";
  std::vector<char> temp_name(temp_path.begin(), temp_path.end());
  temp_name.push_back('\0');
  const int fd = mkstemp(temp_name.data());
  if (fd < 0)
    throw std::runtime_error(path + ": cannot create a file in its folder: " + ErrnoText());
  temp_path = temp_name.data();
  auto fail = [&](const std::string& what) {
    const std::string reason = ErrnoText();
    ::close(fd);
    ::unlink(temp_path.c_str());
    throw std::runtime_error(path + ": " + what + ": " + reason);
  };
  // mkstemp creates the file 0600; maps and ground truth are meant to be shared.
  if (::fchmod(fd, 0644) != 0) fail("cannot set permissions");
  std::size_t written = 0;
  while (written < contents.size()) {
    const ssize_t n = ::write(fd, contents.data() + written, contents.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) fail("write failed");
    written += static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0) fail("fsync failed");
  if (::close(fd) != 0) {
    const std::string reason = ErrnoText();
    ::unlink(temp_path.c_str());
    throw std::runtime_error(path + ": close failed: " + reason);
  }
  if (std::rename(temp_path.c_str(), path.c_str()) != 0) {
    const std::string reason = ErrnoText();
    ::unlink(temp_path.c_str());
    throw std::runtime_error(path + ": cannot rename the temporary file into place: " + reason);
  }
}

}  // namespace json_io
}  // namespace ipm_road_mapper
