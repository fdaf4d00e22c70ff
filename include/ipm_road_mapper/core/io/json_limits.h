// Limits that the map and ground-truth JSON readers enforce, so that a hostile or corrupt
// file fails with a one-line MapFormatError instead of exhausting the stack, memory or time
// (docs/file_formats.md, "Limits"). The text limits are checked on the raw bytes before the
// parse; the element and coordinate limits while the document is converted.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace ipm_road_mapper {
namespace json_limits {

// Largest file the readers open (bytes).
constexpr std::uintmax_t kMaxFileBytes = 512ull * 1024 * 1024;
// Deepest nesting of arrays and objects (the formats themselves need 5 levels).
constexpr int kMaxDepth = 64;
// Most elements in any one array or members in any one object.
constexpr std::size_t kMaxContainerElements = 10'000'000;
// Most JSON values in a whole document.
constexpr std::size_t kMaxValues = 60'000'000;
// Largest distance of any coordinate (point, corner, translation) from the origin (m).
constexpr double kMaxCoordinateM = 1e7;

// Element limits of the formats: markings and lanes per file, control points per lane and
// in the whole map, ground-truth lane points in the whole file, poses and frames.
constexpr std::size_t kMaxMarkings = 100'000;
constexpr std::size_t kMaxLanes = 100'000;
constexpr std::size_t kMaxControlPointsPerLane = 10'000;
constexpr std::size_t kMaxControlPoints = 1'000'000;
constexpr std::size_t kMaxGroundTruthLanePoints = 10'000'000;
constexpr std::size_t kMaxPoses = 10'000'000;

// Checks the raw text of a JSON document against kMaxDepth, kMaxContainerElements and
// kMaxValues without building it (a linear scan with no recursion). Returns "" when it is
// within them, else the reason with the JSON path of the offending container
// ("metadata.a.b: nesting deeper than 64 levels"). Syntax errors are left to the parser.
std::string ScanJsonText(const std::string& text);

}  // namespace json_limits
}  // namespace ipm_road_mapper
