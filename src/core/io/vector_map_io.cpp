// Map JSON reading and writing (format: docs/file_formats.md).
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <set>
#include <sstream>
#include <stdexcept>

#include "ipm_road_mapper/core/io/json_limits.h"
#include "ipm_road_mapper/core/map/vector_map.h"
#include "json_io.h"

namespace ipm_road_mapper {
namespace {

using json_io::Fail;
using json_io::Index;
using json_io::Key;
using json_io::Member;

constexpr char kMapFormat[] = "ipm_road_mapper/vector_map";
// Indentation of the saved file: one level per nesting, small but still diff-able.
constexpr int kMapIndent = 1;

nlohmann::json MarkingToJson(const MapMarking& m) {
  nlohmann::json corners = nlohmann::json::array();
  for (const Eigen::Vector3d& c : m.corners_map) corners.push_back(json_io::Vector3ToJson(c));
  return {{"id", m.id},
          {"class_id", m.class_id},
          {"class_name", m.class_name},
          {"corners", corners},
          {"observations", m.observations},
          {"first_seen", m.first_seen},
          {"last_seen", m.last_seen},
          {"complete", m.Complete()},
          {"sides_measured",
           {m.sides_measured[0], m.sides_measured[1], m.sides_measured[2], m.sides_measured[3]}}};
}

nlohmann::json LaneToJson(const MapLane& lane) {
  nlohmann::json points = nlohmann::json::array();
  for (const Eigen::Vector3d& c : lane.control_points_map) {
    points.push_back(json_io::Vector3ToJson(c));
  }
  nlohmann::json unmeasured = nlohmann::json::array();
  for (const auto& [first, last] : lane.unmeasured) unmeasured.push_back({first, last});
  return {{"id", lane.id},
          {"class_id", lane.class_id},
          {"class_name", lane.class_name},
          {"style", lane.style},
          {"control_points", points},
          {"unmeasured", unmeasured},
          {"observations", lane.observations},
          {"first_seen", lane.first_seen},
          {"last_seen", lane.last_seen},
          {"predecessors", lane.predecessors},
          {"successors", lane.successors}};
}

// An optional array of lane ids (`predecessors`, `successors`); empty when absent.
std::vector<std::uint64_t> OptionalIds(const nlohmann::json& j, const char* key,
                                       const std::string& where) {
  std::vector<std::uint64_t> ids;
  if (!j.contains(key)) return ids;
  const std::string ids_where = Key(where, key);
  const nlohmann::json& array = json_io::ReadArray(j.at(key), ids_where);
  for (std::size_t k = 0; k < array.size(); ++k) {
    ids.push_back(json_io::ReadUint64(array[k], Index(ids_where, k)));
  }
  return ids;
}

// The optional `unmeasured` ranges of a lane with `count` control points: [first, last]
// index pairs, ascending and disjoint, within the points; empty when absent.
std::vector<std::pair<std::size_t, std::size_t>> OptionalRanges(const nlohmann::json& j,
                                                                std::size_t count,
                                                                const std::string& where) {
  std::vector<std::pair<std::size_t, std::size_t>> ranges;
  if (!j.contains("unmeasured")) return ranges;
  const std::string ranges_where = Key(where, "unmeasured");
  const nlohmann::json& array = json_io::ReadArray(j.at("unmeasured"), ranges_where);
  for (std::size_t k = 0; k < array.size(); ++k) {
    const std::string range_where = Index(ranges_where, k);
    const nlohmann::json& pair = json_io::ReadArray(array[k], range_where);
    if (pair.size() != 2) Fail(range_where, "expected [first, last]");
    const std::uint64_t first = json_io::ReadUint64(pair[0], Index(range_where, 0));
    const std::uint64_t last = json_io::ReadUint64(pair[1], Index(range_where, 1));
    if (first > last || last >= count) {
      Fail(range_where,
           "expected first <= last < " + std::to_string(count) + " (the lane's control points)");
    }
    if (!ranges.empty() && first <= ranges.back().second) {
      Fail(range_where, "ranges must ascend without overlap");
    }
    ranges.emplace_back(first, last);
  }
  return ranges;
}

MapMarking MarkingFromJson(const nlohmann::json& j, const std::string& where) {
  MapMarking m;
  m.id = json_io::ReadUint64(Member(j, "id", where), Key(where, "id"));
  m.class_id = json_io::ReadInt(Member(j, "class_id", where), Key(where, "class_id"));
  m.class_name = json_io::OptionalString(j, "class_name", "", where);
  const std::string corners_where = Key(where, "corners");
  const nlohmann::json& corners = json_io::ReadArray(Member(j, "corners", where), corners_where);
  if (corners.size() != 4) {
    Fail(corners_where, "expected 4 corners, got " + std::to_string(corners.size()));
  }
  for (std::size_t k = 0; k < 4; ++k) {
    m.corners_map[k] = json_io::ReadVector3(corners[k], Index(corners_where, k));
  }
  m.observations = json_io::OptionalInt(j, "observations", 0, where);
  m.first_seen = json_io::OptionalNumber(j, "first_seen", 0.0, where);
  m.last_seen = json_io::OptionalNumber(j, "last_seen", 0.0, where);
  // Older maps have no side flags: every marking was a whole view.
  if (j.contains("sides_measured")) {
    const std::string sides_where = Key(where, "sides_measured");
    const nlohmann::json& sides = json_io::ReadArray(j.at("sides_measured"), sides_where);
    if (sides.size() != 4) {
      Fail(sides_where, "expected 4 flags, got " + std::to_string(sides.size()));
    }
    for (std::size_t k = 0; k < 4; ++k) {
      if (!sides[k].is_boolean()) Fail(Index(sides_where, k), "expected true or false");
      m.sides_measured[k] = sides[k].get<bool>();
    }
  } else if (j.contains("complete")) {
    if (!j.at("complete").is_boolean()) Fail(Key(where, "complete"), "expected true or false");
    m.sides_measured.fill(j.at("complete").get<bool>());
  }
  return m;
}

MapLane LaneFromJson(const nlohmann::json& j, const std::string& where) {
  MapLane lane;
  lane.id = json_io::ReadUint64(Member(j, "id", where), Key(where, "id"));
  lane.class_id = json_io::ReadInt(Member(j, "class_id", where), Key(where, "class_id"));
  lane.class_name = json_io::OptionalString(j, "class_name", "", where);
  lane.style = json_io::OptionalString(j, "style", "", where);
  const std::string points_where = Key(where, "control_points");
  const nlohmann::json& points = json_io::ReadArray(
      Member(j, "control_points", where), points_where, json_limits::kMaxControlPointsPerLane);
  if (points.size() < 4) {
    Fail(points_where, "a lane needs at least 4 control points (2 of them phantom ends), got " +
                           std::to_string(points.size()));
  }
  for (std::size_t k = 0; k < points.size(); ++k) {
    lane.control_points_map.push_back(json_io::ReadVector3(points[k], Index(points_where, k)));
  }
  lane.unmeasured = OptionalRanges(j, lane.control_points_map.size(), where);
  lane.observations = json_io::OptionalInt(j, "observations", 0, where);
  lane.first_seen = json_io::OptionalNumber(j, "first_seen", 0.0, where);
  lane.last_seen = json_io::OptionalNumber(j, "last_seen", 0.0, where);
  lane.predecessors = OptionalIds(j, "predecessors", where);
  lane.successors = OptionalIds(j, "successors", where);
  return lane;
}

}  // namespace

nlohmann::json PoseToJson(const Eigen::Isometry3d& T) {
  Eigen::Quaterniond q(T.linear());
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();  // canonical sign: same rotation, stable bytes
  return {{"t", json_io::Vector3ToJson(T.translation())}, {"q_xyzw", {q.x(), q.y(), q.z(), q.w()}}};
}

Eigen::Isometry3d PoseFromJson(const nlohmann::json& j) { return json_io::ReadPose(j, ""); }

namespace {

nlohmann::json GeoOriginToJson(const GeoOrigin& origin) {
  return {{"latitude_deg", origin.latitude_deg},
          {"longitude_deg", origin.longitude_deg},
          {"altitude_m", origin.altitude_m},
          {"heading_deg", origin.heading_deg}};
}

// A number within [-limit, limit] (ReadNumber checks that it is finite).
double ReadBounded(const nlohmann::json& j, const char* key, double limit,
                   const std::string& where) {
  const std::string at = Key(where, key);
  const double value = json_io::ReadNumber(Member(j, key, where), at);
  if (std::abs(value) > limit)
    Fail(at, "must be in [-" + std::to_string(limit) + ", " + std::to_string(limit) + "]");
  return value;
}

GeoOrigin GeoOriginFromJson(const nlohmann::json& j, const std::string& where) {
  if (!j.is_object()) Fail(where, "expected an object");
  GeoOrigin origin;
  origin.latitude_deg = ReadBounded(j, "latitude_deg", 90.0, where);
  origin.longitude_deg = ReadBounded(j, "longitude_deg", 180.0, where);
  origin.altitude_m = json_io::OptionalNumber(j, "altitude_m", 0.0, where);
  origin.heading_deg =
      j.contains("heading_deg") ? ReadBounded(j, "heading_deg", 360.0, where) : 0.0;
  return origin;
}

// The calibration block: {"axes": [...], "covariance": [36, row-major], "observed": [6]}.
nlohmann::json CalibrationToJson(const VectorMap& map) {
  nlohmann::json covariance = nlohmann::json::array();
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 6; ++c) covariance.push_back(map.T_base_cam_covariance(r, c));
  }
  nlohmann::json observed = nlohmann::json::array();
  for (bool o : map.T_base_cam_observed) observed.push_back(o);
  return {{"axes", {"roll", "pitch", "yaw", "x", "y", "z"}},
          {"covariance", covariance},
          {"observed", observed}};
}

void CalibrationFromJson(const nlohmann::json& j, VectorMap* map) {
  const std::string where = "T_base_cam_calibration";
  if (!j.is_object()) Fail(where, "expected an object");
  const nlohmann::json& covariance =
      json_io::ReadArray(Member(j, "covariance", where), Key(where, "covariance"), 36);
  if (covariance.size() != 36) Fail(Key(where, "covariance"), "expected 36 numbers");
  for (int i = 0; i < 36; ++i) {
    map->T_base_cam_covariance(i / 6, i % 6) =
        json_io::ReadNumber(covariance[i], Index(Key(where, "covariance"), i));
  }
  const nlohmann::json& observed =
      json_io::ReadArray(Member(j, "observed", where), Key(where, "observed"), 6);
  if (observed.size() != 6) Fail(Key(where, "observed"), "expected 6 booleans");
  for (int i = 0; i < 6; ++i) {
    if (!observed[i].is_boolean()) Fail(Index(Key(where, "observed"), i), "expected a boolean");
    map->T_base_cam_observed[i] = observed[i].get<bool>();
  }
}

}  // namespace

nlohmann::json VectorMapToJson(const VectorMap& map) {
  nlohmann::json markings = nlohmann::json::array();
  for (const MapMarking& m : map.markings) markings.push_back(MarkingToJson(m));
  nlohmann::json lanes = nlohmann::json::array();
  for (const MapLane& lane : map.lanes) lanes.push_back(LaneToJson(lane));
  nlohmann::json trajectory = nlohmann::json::array();
  for (const StampedPose& pose : map.trajectory) {
    nlohmann::json entry = PoseToJson(pose.T_map_base);
    entry["stamp"] = pose.stamp;
    trajectory.push_back(std::move(entry));
  }
  nlohmann::json j = {{"format", kMapFormat},
                      {"version", kVectorMapFormatVersion},
                      {"frame_id", map.frame_id},
                      {"T_base_cam", PoseToJson(map.T_base_cam)},
                      {"T_base_cam_initial", PoseToJson(map.T_base_cam_initial)},
                      {"T_base_cam_calibration", CalibrationToJson(map)},
                      {"markings", markings},
                      {"lanes", lanes},
                      {"trajectory", trajectory},
                      {"metadata", map.metadata}};
  if (map.geo_origin) j["geo_origin"] = GeoOriginToJson(*map.geo_origin);
  return j;
}

VectorMap VectorMapFromJson(const nlohmann::json& j) {
  json_io::CheckFormatHeader(j, kMapFormat, kVectorMapFormatVersion);
  VectorMap map;
  map.frame_id = json_io::OptionalString(j, "frame_id", "map", "");
  map.T_base_cam = json_io::ReadPose(Member(j, "T_base_cam", ""), "T_base_cam");
  map.T_base_cam_initial =
      json_io::ReadPose(Member(j, "T_base_cam_initial", ""), "T_base_cam_initial");
  // Optional: maps written before it have none (zero covariance, nothing observed).
  if (j.contains("T_base_cam_calibration")) CalibrationFromJson(j["T_base_cam_calibration"], &map);

  std::set<std::uint64_t> marking_ids;
  const nlohmann::json& markings =
      json_io::ReadArray(Member(j, "markings", ""), "markings", json_limits::kMaxMarkings);
  for (std::size_t i = 0; i < markings.size(); ++i) {
    map.markings.push_back(MarkingFromJson(markings[i], Index("markings", i)));
    if (!marking_ids.insert(map.markings.back().id).second) {
      Fail(Index("markings", i), "duplicate id " + std::to_string(map.markings.back().id));
    }
  }
  std::set<std::uint64_t> lane_ids;
  const nlohmann::json& lanes =
      json_io::ReadArray(Member(j, "lanes", ""), "lanes", json_limits::kMaxLanes);
  std::size_t control_points = 0;
  for (std::size_t i = 0; i < lanes.size(); ++i) {
    map.lanes.push_back(LaneFromJson(lanes[i], Index("lanes", i)));
    control_points += map.lanes.back().control_points_map.size();
    if (control_points > json_limits::kMaxControlPoints) {
      Fail(Index("lanes", i), "more than " + std::to_string(json_limits::kMaxControlPoints) +
                                  " control points in the map");
    }
    if (!lane_ids.insert(map.lanes.back().id).second) {
      Fail(Index("lanes", i), "duplicate id " + std::to_string(map.lanes.back().id));
    }
  }
  // Topology never names the lane itself; it may name lanes outside the file (a map cut into
  // parts keeps each lane's links).
  for (std::size_t i = 0; i < map.lanes.size(); ++i) {
    const MapLane& lane = map.lanes[i];
    for (const auto* ids : {&lane.predecessors, &lane.successors}) {
      if (std::find(ids->begin(), ids->end(), lane.id) != ids->end()) {
        Fail(Index("lanes", i), "topology names the lane itself");
      }
    }
  }
  if (j.contains("trajectory")) {
    const nlohmann::json& trajectory =
        json_io::ReadArray(j["trajectory"], "trajectory", json_limits::kMaxPoses);
    for (std::size_t i = 0; i < trajectory.size(); ++i) {
      const std::string where = Index("trajectory", i);
      StampedPose pose;
      pose.stamp = json_io::ReadNumber(Member(trajectory[i], "stamp", where), Key(where, "stamp"));
      pose.T_map_base = json_io::ReadPose(trajectory[i], where);
      map.trajectory.push_back(pose);
    }
  }
  if (j.contains("metadata")) {
    if (!j["metadata"].is_object()) Fail("metadata", "expected an object");
    // The copy below recurses: bound the depth first (ParseJsonFile did for files).
    json_io::CheckDepth(j["metadata"], json_limits::kMaxDepth - 1, "metadata");
    map.metadata = j["metadata"];
  }
  if (j.contains("geo_origin")) map.geo_origin = GeoOriginFromJson(j["geo_origin"], "geo_origin");
  return map;
}

void SaveVectorMapJson(const VectorMap& map, const std::string& path) {
  const nlohmann::json j = VectorMapToJson(map);
  // Refuse what the reader would reject (NaN, too few control points, duplicate ids), so a
  // saved map always loads again.
  try {
    VectorMapFromJson(j);
  } catch (const MapFormatError& e) {
    throw std::runtime_error(path + ": cannot save map: " + e.what());
  }
  json_io::WriteFileAtomically(path, j.dump(kMapIndent) + "\n");
}

VectorMap LoadVectorMapJson(const std::string& path) {
  const nlohmann::json j = json_io::ParseJsonFile(path);
  try {
    return VectorMapFromJson(j);
  } catch (const MapFormatError& e) {
    throw MapFormatError(path + ": " + e.what());
  }
}

void WriteTumTrajectory(const std::vector<StampedPose>& poses, const std::string& path) {
  std::ostringstream out;
  out << std::fixed;
  for (const StampedPose& pose : poses) {
    Eigen::Quaterniond q(pose.T_map_base.linear());
    if (q.w() < 0.0) q.coeffs() = -q.coeffs();
    const Eigen::Vector3d& t = pose.T_map_base.translation();
    out << std::setprecision(9) << pose.stamp << std::setprecision(6) << ' ' << t.x() << ' '
        << t.y() << ' ' << t.z() << std::setprecision(9) << ' ' << q.x() << ' ' << q.y() << ' '
        << q.z() << ' ' << q.w() << '\n';
  }
  json_io::WriteFileAtomically(path, out.str());
}

}  // namespace ipm_road_mapper
