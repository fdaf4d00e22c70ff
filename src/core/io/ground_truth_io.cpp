// Ground-truth JSON reading and writing (format: docs/file_formats.md). The writer is
// deterministic: keys in a fixed (alphabetical) order, lengths rounded to 1e-6 m, quaternion
// coefficients to 1e-9 with a canonical sign, stamps to 1 ns, so the same drive gives the
// same bytes.
#include <limits>
#include <stdexcept>

#include "ipm_road_mapper/core/io/ground_truth.h"
#include "ipm_road_mapper/core/io/json_limits.h"
#include "ipm_road_mapper/core/map/vector_map.h"
#include "json_io.h"

namespace ipm_road_mapper {
namespace {

using json_io::Fail;
using json_io::Index;
using json_io::Key;
using json_io::Member;

constexpr char kGroundTruthFormat[] = "ipm_road_mapper/ground_truth";
constexpr int kLengthDecimals = 6;  // 1e-6 m
constexpr int kQuaternionDecimals = 9;
constexpr int kStampDecimals = 9;  // 1 ns, the resolution of ros::Time
constexpr int kIndent = 1;
constexpr int kMaxImageSidePx = 16384;  // the largest camera image side a file may state

nlohmann::json RoundedPose(const Eigen::Isometry3d& T) {
  nlohmann::json j = PoseToJson(T);
  j["t"] = json_io::Vector3ToJson(T.translation(), kLengthDecimals);
  for (auto& q : j["q_xyzw"]) q = json_io::RoundToDecimals(q.get<double>(), kQuaternionDecimals);
  return j;
}

// The pose under `key` of `parent`.
Eigen::Isometry3d ReadPose(const nlohmann::json& parent, const char* key,
                           const std::string& where) {
  return json_io::ReadPose(Member(parent, key, where), Key(where, key));
}

nlohmann::json CameraToJson(const CameraIntrinsics& c) {
  return {{"width", c.width}, {"height", c.height},        {"fx", c.fx}, {"fy", c.fy}, {"cx", c.cx},
          {"cy", c.cy},       {"distortion", c.distortion}};
}

CameraIntrinsics CameraFromJson(const nlohmann::json& j, const std::string& where) {
  CameraIntrinsics c;
  c.width = json_io::ReadInt(Member(j, "width", where), Key(where, "width"));
  c.height = json_io::ReadInt(Member(j, "height", where), Key(where, "height"));
  // The evaluator walks a pixel grid over the image: an absurd size would never finish.
  for (const auto& [key, size] : {std::pair{"width", c.width}, std::pair{"height", c.height}}) {
    if (size < 1 || size > kMaxImageSidePx) {
      Fail(Key(where, key),
           std::to_string(size) + " px is outside [1, " + std::to_string(kMaxImageSidePx) + "]");
    }
  }
  c.fx = json_io::ReadNumber(Member(j, "fx", where), Key(where, "fx"));
  c.fy = json_io::ReadNumber(Member(j, "fy", where), Key(where, "fy"));
  c.cx = json_io::ReadNumber(Member(j, "cx", where), Key(where, "cx"));
  c.cy = json_io::ReadNumber(Member(j, "cy", where), Key(where, "cy"));
  const std::string d_where = Key(where, "distortion");
  const nlohmann::json& d = json_io::ReadArray(Member(j, "distortion", where), d_where);
  if (d.size() != c.distortion.size()) Fail(d_where, "expected [k1, k2, p1, p2, k3]");
  for (std::size_t k = 0; k < d.size(); ++k) {
    c.distortion[k] = json_io::ReadNumber(d[k], Index(d_where, k));
  }
  const std::string problem = PinholeCamera(c).Validate();
  if (!problem.empty()) Fail(where, problem);
  return c;
}

nlohmann::json MarkingToJson(const GroundTruthMarking& m) {
  nlohmann::json corners = nlohmann::json::array();
  for (const Eigen::Vector3d& c : m.corners_map) {
    corners.push_back(json_io::Vector3ToJson(c, kLengthDecimals));
  }
  return {{"id", m.id},
          {"class_id", m.class_id},
          {"class_name", m.class_name},
          {"corners", corners},
          {"center", json_io::Vector3ToJson(m.center_map, kLengthDecimals)},
          {"visible_frames", m.visible_frames}};
}

GroundTruthMarking MarkingFromJson(const nlohmann::json& j, const std::string& where) {
  GroundTruthMarking m;
  m.id = json_io::ReadInt(Member(j, "id", where), Key(where, "id"));
  m.class_id = json_io::ReadInt(Member(j, "class_id", where), Key(where, "class_id"));
  m.class_name = json_io::OptionalString(j, "class_name", "", where);
  const std::string corners_where = Key(where, "corners");
  const nlohmann::json& corners = json_io::ReadArray(Member(j, "corners", where), corners_where);
  if (corners.size() != 4) {
    Fail(corners_where, "expected 4 corners, got " + std::to_string(corners.size()));
  }
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < 4; ++k) {
    m.corners_map[k] = json_io::ReadVector3(corners[k], Index(corners_where, k));
    sum += m.corners_map[k];
  }
  m.center_map = j.contains("center") ? json_io::ReadVector3(j["center"], Key(where, "center"))
                                      : Eigen::Vector3d(0.25 * sum);
  m.visible_frames =
      json_io::ReadInt(Member(j, "visible_frames", where), Key(where, "visible_frames"));
  return m;
}

nlohmann::json LaneToJson(const GroundTruthLane& lane) {
  nlohmann::json points = nlohmann::json::array();
  for (const Eigen::Vector3d& p : lane.points_map) {
    points.push_back(json_io::Vector3ToJson(p, kLengthDecimals));
  }
  return {{"id", lane.id},
          {"class_id", lane.class_id},
          {"class_name", lane.class_name},
          {"style", lane.style},
          {"points", points}};
}

GroundTruthLane LaneFromJson(const nlohmann::json& j, const std::string& where) {
  GroundTruthLane lane;
  lane.id = json_io::ReadInt(Member(j, "id", where), Key(where, "id"));
  lane.class_id = json_io::ReadInt(Member(j, "class_id", where), Key(where, "class_id"));
  lane.class_name = json_io::OptionalString(j, "class_name", "", where);
  lane.style = json_io::OptionalString(j, "style", "", where);
  const std::string points_where = Key(where, "points");
  const nlohmann::json& points = json_io::ReadArray(Member(j, "points", where), points_where,
                                                    json_limits::kMaxGroundTruthLanePoints);
  if (points.size() < 2) Fail(points_where, "a lane needs at least 2 points");
  lane.points_map.reserve(points.size());
  for (std::size_t k = 0; k < points.size(); ++k) {
    lane.points_map.push_back(json_io::ReadVector3(points[k], Index(points_where, k)));
  }
  return lane;
}

nlohmann::json FrameToJson(const GroundTruthFrame& frame) {
  return {{"stamp", json_io::RoundToDecimals(frame.stamp, kStampDecimals)},
          {"T_map_base_true", RoundedPose(frame.T_map_base_true)},
          {"T_map_base_odom", RoundedPose(frame.T_map_base_odom)}};
}

GroundTruthFrame FrameFromJson(const nlohmann::json& j, const std::string& where) {
  GroundTruthFrame frame;
  frame.stamp = json_io::ReadNumber(Member(j, "stamp", where), Key(where, "stamp"));
  frame.T_map_base_true = ReadPose(j, "T_map_base_true", where);
  frame.T_map_base_odom = ReadPose(j, "T_map_base_odom", where);
  return frame;
}

// Reads the array `key` of the root, converting each element with `from_json`.
template <typename T, typename FromJson>
std::vector<T> ReadList(const nlohmann::json& root, const char* key, std::size_t max_size,
                        FromJson from_json) {
  const nlohmann::json& array = json_io::ReadArray(Member(root, key, ""), key, max_size);
  std::vector<T> items;
  items.reserve(array.size());
  for (std::size_t i = 0; i < array.size(); ++i) {
    items.push_back(from_json(array[i], Index(key, i)));
  }
  return items;
}

GroundTruth GroundTruthFromJson(const nlohmann::json& j) {
  json_io::CheckFormatHeader(j, kGroundTruthFormat, kGroundTruthFormatVersion);
  GroundTruth gt;
  gt.scenario = json_io::ReadString(Member(j, "scenario", ""), "scenario");
  const std::uint64_t seed = json_io::ReadUint64(Member(j, "seed", ""), "seed");
  if (seed > std::numeric_limits<std::uint32_t>::max()) Fail("seed", "out of range");
  gt.seed = static_cast<std::uint32_t>(seed);
  gt.frame_rate_hz = json_io::ReadNumber(Member(j, "frame_rate_hz", ""), "frame_rate_hz");
  gt.camera = CameraFromJson(Member(j, "camera", ""), "camera");
  gt.T_base_cam_true = ReadPose(j, "T_base_cam_true", "");
  gt.T_base_cam_rough = ReadPose(j, "T_base_cam_rough", "");
  gt.markings =
      ReadList<GroundTruthMarking>(j, "markings", json_limits::kMaxMarkings, MarkingFromJson);
  gt.lanes = ReadList<GroundTruthLane>(j, "lanes", json_limits::kMaxLanes, LaneFromJson);
  std::size_t lane_points = 0;
  for (std::size_t i = 0; i < gt.lanes.size(); ++i) {
    lane_points += gt.lanes[i].points_map.size();
    if (lane_points > json_limits::kMaxGroundTruthLanePoints) {
      Fail(Index("lanes", i), "more than " +
                                  std::to_string(json_limits::kMaxGroundTruthLanePoints) +
                                  " lane points in the file");
    }
  }
  gt.frames = ReadList<GroundTruthFrame>(j, "frames", json_limits::kMaxPoses, FrameFromJson);
  return gt;
}

}  // namespace

void SaveGroundTruthJson(const GroundTruth& gt, const std::string& path) {
  nlohmann::json markings = nlohmann::json::array();
  for (const GroundTruthMarking& m : gt.markings) markings.push_back(MarkingToJson(m));
  nlohmann::json lanes = nlohmann::json::array();
  for (const GroundTruthLane& lane : gt.lanes) lanes.push_back(LaneToJson(lane));
  nlohmann::json frames = nlohmann::json::array();
  for (const GroundTruthFrame& frame : gt.frames) frames.push_back(FrameToJson(frame));
  const nlohmann::json j = {{"format", kGroundTruthFormat},
                            {"version", kGroundTruthFormatVersion},
                            {"scenario", gt.scenario},
                            {"seed", gt.seed},
                            {"frame_rate_hz", gt.frame_rate_hz},
                            {"camera", CameraToJson(gt.camera)},
                            {"T_base_cam_true", RoundedPose(gt.T_base_cam_true)},
                            {"T_base_cam_rough", RoundedPose(gt.T_base_cam_rough)},
                            {"markings", markings},
                            {"lanes", lanes},
                            {"frames", frames}};
  // A NaN would be written as null and fail on reading: refuse it here instead.
  try {
    GroundTruthFromJson(j);
  } catch (const MapFormatError& e) {
    throw std::runtime_error(path + ": cannot save ground truth: " + e.what());
  }
  json_io::WriteFileAtomically(path, j.dump(kIndent) + "\n");
}

GroundTruth LoadGroundTruthJson(const std::string& path) {
  const nlohmann::json j = json_io::ParseJsonFile(path);
  try {
    return GroundTruthFromJson(j);
  } catch (const MapFormatError& e) {
    throw MapFormatError(path + ": " + e.what());
  }
}

}  // namespace ipm_road_mapper
