// Internal helpers shared by the map and ground-truth JSON readers and writers: checked
// accessors whose errors name the JSON path ("markings[3].corners[1]: not a finite number"),
// file parsing, and atomic file writing. Not installed; include only from src/core.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

#include "ipm_road_mapper/core/io/json_limits.h"

namespace ipm_road_mapper {
namespace json_io {

// Throws MapFormatError("<where>: <what>").
[[noreturn]] void Fail(const std::string& where, const std::string& what);

// Child path names for error messages: Key("lanes", "id") = "lanes.id", Index("lanes", 2) =
// "lanes[2]".
std::string Key(const std::string& where, const char* key);
std::string Index(const std::string& where, std::size_t index);

// The member `key` of object `j`; fails when `j` is not an object or the key is missing.
const nlohmann::json& Member(const nlohmann::json& j, const char* key, const std::string& where);

// Typed reads of a JSON value at `where`; each fails with a one-line message on a type
// mismatch, a non-finite number (NaN and infinities are stored as null by nlohmann) or a
// value out of range.
double ReadNumber(const nlohmann::json& j, const std::string& where);
int ReadInt(const nlohmann::json& j, const std::string& where);
std::uint64_t ReadUint64(const nlohmann::json& j, const std::string& where);
std::string ReadString(const nlohmann::json& j, const std::string& where);
// An array of at most `max_size` elements.
const nlohmann::json& ReadArray(const nlohmann::json& j, const std::string& where,
                                std::size_t max_size = json_limits::kMaxContainerElements);
// [x, y, z] at most json_limits::kMaxCoordinateM from the origin.
Eigen::Vector3d ReadVector3(const nlohmann::json& j, const std::string& where);
// A pose {"t": [x, y, z], "q_xyzw": [qx, qy, qz, qw]}; the quaternion must be unit within
// 1e-3 and is normalized.
Eigen::Isometry3d ReadPose(const nlohmann::json& j, const std::string& where);

// Optional members: the default when `key` is absent, otherwise a checked read.
double OptionalNumber(const nlohmann::json& j, const char* key, double fallback,
                      const std::string& where);
int OptionalInt(const nlohmann::json& j, const char* key, int fallback, const std::string& where);
std::string OptionalString(const nlohmann::json& j, const char* key, const std::string& fallback,
                           const std::string& where);

// Fails when `j` nests arrays/objects deeper than `max_depth` levels (counting `j` itself);
// iterative, for documents built in memory rather than parsed by ParseJsonFile.
void CheckDepth(const nlohmann::json& j, int max_depth, const std::string& where);

// Checks {"format": format, "version": version} at the root of a document.
void CheckFormatHeader(const nlohmann::json& root, const char* format, int version);

// [x, y, z]; with decimals >= 0, each coordinate rounded to that many decimals (see
// RoundToDecimals), so that writers can produce stable, short bytes.
nlohmann::json Vector3ToJson(const Eigen::Vector3d& v, int decimals = -1);

// The double nearest to `value` rounded to `decimals` decimals (unchanged when decimals < 0
// or the value has no such digits: |value| * 10^decimals >= 2^53); never -0. Dividing the rounded
// integer by 10^decimals (both exact) gives the double nearest to the decimal, which JSON then
// prints in its short form (1.55, not 1.5499999999999998).
double RoundToDecimals(double value, int decimals);

// Reads and parses a JSON file; a missing/unreadable file, one beyond the text limits of
// json_limits.h (size, depth, element counts; checked before the parse) or a syntax error
// (including a truncated file and a number beyond the double range) throws MapFormatError
// naming the file.
nlohmann::json ParseJsonFile(const std::string& path);

// Writes `contents` to a temporary file in the folder of `path`, flushes it to disk and
// renames it over `path`, so readers see either the old or the new file, never a partial one.
// Throws std::runtime_error (and removes the temporary file) on failure.
void WriteFileAtomically(const std::string& path, const std::string& contents);

}  // namespace json_io
}  // namespace ipm_road_mapper
