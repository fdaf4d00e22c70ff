// The vectorized road map as the package exports it: markings as 4-corner polygons, lanes
// as Catmull-Rom control points, all in the `map` frame, plus the refined extrinsic and the
// (corrected) trajectory. The JSON form is specified in docs/file_formats.md.
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "ipm_road_mapper/core/geometry/rigid_transform.h"

namespace ipm_road_mapper {

// Current version of the map JSON format; readers reject other major versions.
constexpr int kVectorMapFormatVersion = 1;

// A ground marking: its bounding rectangle on the road, corners in canonical order
// (counter-clockwise seen from above, starting at the corner nearest the vehicle when first
// mapped).
struct MapMarking {
  std::uint64_t id = 0;
  int class_id = 0;
  std::string class_name;
  std::array<Eigen::Vector3d, 4> corners_map;
  int observations = 0;
  double first_seen = 0.0;  // stamps (s)
  double last_seen = 0.0;
  // Per side (side i from corner i to i + 1): some view saw the marking's boundary there.
  // An unmeasured side is where the views of a marking larger than the view ended: the
  // rectangle is a lower bound of the marking in that direction.
  std::array<bool, 4> sides_measured{{true, true, true, true}};
  // Every side measured: a marking whose extent was closed (false: `complete: false`).
  bool Complete() const {
    return sides_measured[0] && sides_measured[1] && sides_measured[2] && sides_measured[3];
  }
  Eigen::Vector3d Center() const {
    return 0.25 * (corners_map[0] + corners_map[1] + corners_map[2] + corners_map[3]);
  }
};

// A lane line: control points of a uniform Catmull-Rom spline (the first and last are the
// phantom end points; the curve runs from the second to the second-to-last).
struct MapLane {
  std::uint64_t id = 0;
  int class_id = 0;
  std::string class_name;
  std::string style;  // "solid", "dashed" or "" when unknown
  std::vector<Eigen::Vector3d> control_points_map;
  // The control points no pixel measured: laid by a join across a gap in the line's
  // observations (lane_unmeasured.h), as inclusive [first, last] ranges of indices into
  // control_points_map, ascending and disjoint; empty: every point measured.
  std::vector<std::pair<std::size_t, std::size_t>> unmeasured;
  int observations = 0;
  double first_seen = 0.0;
  double last_seen = 0.0;
  // Topology where known (lane_topology.h): ids of the lanes this one continues from (its
  // start lies on their curve: a line that goes on in another class, a fork's branch) and
  // of the lanes that continue it (its end lies on theirs: a merge, a class change).
  std::vector<std::uint64_t> predecessors;
  std::vector<std::uint64_t> successors;
};

// Where the map frame's origin is on the Earth (config section `geo_origin`), and how it is
// turned there: the map frame's x axis points `heading_deg` counter-clockwise from east
// (z up), so 0 means the map frame is ENU (x east, y north, z up).
struct GeoOrigin {
  double latitude_deg = 0.0;   // WGS84, north positive, [-90, 90]
  double longitude_deg = 0.0;  // WGS84, east positive, [-180, 180]
  double altitude_m = 0.0;     // height above the WGS84 ellipsoid
  double heading_deg = 0.0;    // map x axis from east, counter-clockwise, [-360, 360]
};

// The whole exported map.
struct VectorMap {
  std::string frame_id = "map";
  std::vector<MapMarking> markings;
  std::vector<MapLane> lanes;
  Eigen::Isometry3d T_base_cam = Eigen::Isometry3d::Identity();          // refined
  Eigen::Isometry3d T_base_cam_initial = Eigen::Isometry3d::Identity();  // as handed in
  // The refined extrinsic's calibration. Covariance over (roll, pitch, yaw, x, y, z): the
  // rotation error as a rotation vector about base_link's axes (R_true = Exp(e) R, rad),
  // then the translation (m). Observed: whether the data observed that axis (the others
  // stayed at their prior, extrinsic_observability.h).
  Eigen::Matrix<double, 6, 6> T_base_cam_covariance = Eigen::Matrix<double, 6, 6>::Zero();
  std::array<bool, 6> T_base_cam_observed{};
  std::vector<StampedPose> trajectory;                 // corrected T_map_base per processed frame
  nlohmann::json metadata = nlohmann::json::object();  // method, config, counters, origin
  std::optional<GeoOrigin> geo_origin;                 // when the map frame is geo-referenced
};

// Thrown when a map file cannot be read or does not follow the format; what() is one line.
class MapFormatError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// JSON conversion (exposed for tests and for tools that embed maps).
nlohmann::json VectorMapToJson(const VectorMap& map);
VectorMap VectorMapFromJson(const nlohmann::json& j);  // throws MapFormatError

// Writes the map atomically (temporary file in the same folder, then rename). Throws
// std::runtime_error when the folder is not writable.
void SaveVectorMapJson(const VectorMap& map, const std::string& path);

// Reads a map file. Throws MapFormatError (missing file, bad JSON, wrong version, NaN,
// a marking without 4 corners, a lane with fewer than 4 control points, ...).
VectorMap LoadVectorMapJson(const std::string& path);

// Pose <-> JSON: {"t": [x, y, z], "q_xyzw": [qx, qy, qz, qw]}.
nlohmann::json PoseToJson(const Eigen::Isometry3d& T);
Eigen::Isometry3d PoseFromJson(const nlohmann::json& j);  // throws MapFormatError

// Writes a trajectory in TUM format ("stamp tx ty tz qx qy qz qw" per line).
void WriteTumTrajectory(const std::vector<StampedPose>& poses, const std::string& path);

}  // namespace ipm_road_mapper
