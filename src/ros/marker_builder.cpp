#include "ipm_road_mapper/ros/marker_builder.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <exception>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "ipm_road_mapper/core/map/lane_samples.h"
#include "ipm_road_mapper/ros/element_fingerprint.h"
#include "ipm_road_mapper/ros/msg_conversion.h"

namespace ipm_road_mapper {
namespace {

// The marker namespaces, by index (a marker's key is its namespace index and id).
constexpr std::array<const char*, 4> kNamespaces = {"lanes", "lane_control_points", "markings",
                                                    "marking_labels"};
constexpr std::size_t kLaneNs = 0, kControlPointNs = 1, kMarkingNs = 2, kLabelNs = 3;

std::uint64_t Key(std::size_t ns, int id) {
  return (static_cast<std::uint64_t>(ns) << 32) | static_cast<std::uint32_t>(id);
}

std_msgs::ColorRGBA Rgba(float r, float g, float b, float a = 1.0f) {
  std_msgs::ColorRGBA c;
  c.r = r;
  c.g = g;
  c.b = b;
  c.a = a;
  return c;
}

// Where a lane line is laid, not measured (MapLane::unmeasured).
const std_msgs::ColorRGBA kUnmeasuredColor = Rgba(0.5f, 0.5f, 0.5f, 0.5f);

int MarkerId(std::uint64_t element_id) { return static_cast<int>(element_id & 0x7fffffffu); }

visualization_msgs::Marker NewMarker(const std::string& ns, int id, int type,
                                     const std::string& frame_id, const ros::Time& stamp) {
  visualization_msgs::Marker m;
  m.header.frame_id = frame_id;
  m.header.stamp = stamp;
  m.ns = ns;
  m.id = id;
  m.type = type;
  m.action = visualization_msgs::Marker::ADD;
  m.pose.orientation.w = 1.0;
  m.frame_locked = false;
  return m;
}

// Points along the curve of control points [first, last) (segments first .. last - 4); the
// control points themselves when no spline can be built (fewer than 4 or non-finite points).
// The curve of control points [first, last) sampled every spacing_m, with per sample whether
// it lies on a stretch no pixel measured (lane_samples.h; `unmeasured` per control point).
LaneSamples CurveSamples(const std::vector<Eigen::Vector3d>& control_points, std::size_t first,
                         std::size_t last, double spacing_m, const std::vector<bool>& unmeasured) {
  const std::vector<Eigen::Vector3d> part(control_points.begin() + first,
                                          control_points.begin() + last);
  const std::vector<bool> part_unmeasured(unmeasured.begin() + first, unmeasured.begin() + last);
  try {
    return SampleLane(part, part_unmeasured, spacing_m);
  } catch (const std::exception&) {
    return {part, part_unmeasured};
  }
}

}  // namespace

std_msgs::ColorRGBA ClassColor(int class_id, const std::string& class_name) {
  if (class_name.find("yellow") != std::string::npos) return Rgba(1.0f, 0.85f, 0.1f);
  if (class_name.find("white") != std::string::npos) return Rgba(0.95f, 0.95f, 0.95f);
  static const std::array<std::array<float, 3>, 12> kPalette = {{{0.90f, 0.10f, 0.29f},
                                                                 {0.24f, 0.71f, 0.29f},
                                                                 {0.26f, 0.39f, 0.85f},
                                                                 {0.96f, 0.51f, 0.19f},
                                                                 {0.57f, 0.12f, 0.71f},
                                                                 {0.27f, 0.94f, 0.94f},
                                                                 {0.94f, 0.20f, 0.90f},
                                                                 {0.74f, 0.96f, 0.05f},
                                                                 {0.98f, 0.75f, 0.83f},
                                                                 {0.0f, 0.50f, 0.50f},
                                                                 {0.60f, 0.39f, 0.14f},
                                                                 {0.50f, 0.0f, 0.0f}}};
  const auto& c =
      kPalette[static_cast<std::size_t>(class_id < 0 ? -class_id : class_id) % kPalette.size()];
  return Rgba(c[0], c[1], c[2]);
}

int LaneChunkMarkerId(std::uint64_t lane_id, std::size_t chunk) {
  return static_cast<int>(((lane_id & 0x1fffffu) << 10) | (chunk & 0x3ffu));
}

std::size_t LaneChunkCount(std::size_t control_points, std::size_t chunk_segments) {
  chunk_segments = std::max<std::size_t>(chunk_segments, 1);
  if (control_points < 4) return 1;
  return (control_points - 3 + chunk_segments - 1) / chunk_segments;
}

LaneChunk LaneChunkAt(std::size_t control_points, std::size_t chunk_segments, std::size_t index) {
  chunk_segments = std::max<std::size_t>(chunk_segments, 1);
  if (control_points < 4) return {0, 0, control_points, 0, control_points};
  const std::size_t segments = control_points - 3;
  const std::size_t first = index * chunk_segments;
  const std::size_t end = std::min(first + chunk_segments, segments);
  const bool last = end == segments;
  return {index, first, end + 3, first, last ? control_points : end};
}

std::vector<LaneChunk> LaneChunks(std::size_t control_points, std::size_t chunk_segments) {
  std::vector<LaneChunk> chunks;
  const std::size_t count = LaneChunkCount(control_points, chunk_segments);
  for (std::size_t i = 0; i < count; ++i) {
    chunks.push_back(LaneChunkAt(control_points, chunk_segments, i));
  }
  return chunks;
}

MarkerBuilder::MarkerBuilder(double lane_sample_spacing_m, std::size_t lane_chunk_segments)
    : lane_sample_spacing_m_(lane_sample_spacing_m > 0.0 ? lane_sample_spacing_m : 0.5),
      lane_chunk_segments_(std::max<std::size_t>(lane_chunk_segments, 1)) {}

void MarkerBuilder::Add(std::size_t ns, std::size_t fingerprint, visualization_msgs::Marker marker,
                        visualization_msgs::MarkerArray* out) {
  published_[Key(ns, marker.id)] = {fingerprint, generation_};
  out->markers.push_back(std::move(marker));
}

bool MarkerBuilder::Unchanged(std::size_t ns_a, std::size_t ns_b, int id, std::size_t fingerprint,
                              Mode mode) {
  if (mode != Mode::kChanges) return false;
  bool any = false, same = true;
  for (const std::size_t ns : {ns_a, ns_b}) {
    const auto it = published_.find(Key(ns, id));
    if (it == published_.end()) continue;
    any = true;
    same = same && it->second.fingerprint == fingerprint;
  }
  if (!any || !same) return false;
  for (const std::size_t ns : {ns_a, ns_b}) {
    const auto it = published_.find(Key(ns, id));
    if (it != published_.end()) it->second.generation = generation_;
  }
  return true;
}

std::size_t MarkerBuilder::AddLane(const MapLane& lane, std::size_t first_changed,
                                   std::size_t offset, const std::string& frame_id,
                                   const ros::Time& stamp, Mode mode,
                                   visualization_msgs::MarkerArray* out) {
  using visualization_msgs::Marker;
  const std::vector<Eigen::Vector3d>& cps = lane.control_points_map;
  const std::size_t points = offset + cps.size();
  const std_msgs::ColorRGBA color = ClassColor(lane.class_id, lane.class_name);
  const std::size_t count = LaneChunkCount(points, lane_chunk_segments_);
  std::size_t& drawn = lane_chunks_[lane.id];
  drawn = std::max(drawn, count);
  const std::vector<bool> unmeasured = UnmeasuredPointFlags(lane);
  // The first chunk whose curve (points [curve_first, curve_first + segments + 3)) reaches
  // the first changed point; the earlier ones are as drawn.
  const std::size_t first_chunk =
      first_changed < 3 ? 0 : std::min((first_changed - 3) / lane_chunk_segments_, count);
  if (first_chunk < count &&
      LaneChunkAt(points, lane_chunk_segments_, first_chunk).curve_first < offset) {
    throw std::invalid_argument("MarkerBuilder: lane " + std::to_string(lane.id) +
                                " came without the points its first changed chunk needs");
  }
  for (std::size_t index = first_chunk; index < count; ++index) {
    const LaneChunk chunk = LaneChunkAt(points, lane_chunk_segments_, index);
    const std::size_t curve_first = chunk.curve_first - offset;
    const std::size_t curve_last = chunk.curve_last - offset;
    const int id = LaneChunkMarkerId(lane.id, chunk.index);
    const std::size_t fingerprint = GeometryFingerprint(lane, curve_first, curve_last);
    work_.points_fingerprinted += curve_last - curve_first;
    if (Unchanged(kLaneNs, kControlPointNs, id, fingerprint, mode)) continue;
    work_.points_drawn += curve_last - curve_first;
    Marker line = NewMarker(kNamespaces[kLaneNs], id, Marker::LINE_STRIP, frame_id, stamp);
    line.scale.x = 0.15;  // line width, m (a painted lane line)
    line.color = color;
    const LaneSamples samples =
        CurveSamples(cps, curve_first, curve_last, lane_sample_spacing_m_, unmeasured);
    for (const Eigen::Vector3d& p : samples.points) line.points.push_back(ToPointMsg(p));
    // A stretch no pixel measured (laid by a join) is drawn grey and faint.
    const std::vector<bool>& laid = samples.unmeasured;
    if (std::find(laid.begin(), laid.end(), true) != laid.end()) {
      for (const bool l : laid) line.colors.push_back(l ? kUnmeasuredColor : color);
    }
    if (line.points.size() >= 2) Add(kLaneNs, fingerprint, std::move(line), out);
    Marker points_marker =
        NewMarker(kNamespaces[kControlPointNs], id, Marker::SPHERE_LIST, frame_id, stamp);
    points_marker.scale.x = points_marker.scale.y = points_marker.scale.z = 0.3;
    points_marker.color = Rgba(color.r * 0.6f, color.g * 0.6f, color.b * 0.6f + 0.4f);
    for (std::size_t i = chunk.points_first; i < chunk.points_last; ++i) {
      points_marker.points.push_back(ToPointMsg(cps[i - offset]));
    }
    if (!points_marker.points.empty()) {
      Add(kControlPointNs, fingerprint, std::move(points_marker), out);
    }
  }
  return first_chunk;
}

void MarkerBuilder::AddMarking(const MapMarking& marking, const std::string& frame_id,
                               const ros::Time& stamp, Mode mode,
                               visualization_msgs::MarkerArray* out) {
  using visualization_msgs::Marker;
  const int id = MarkerId(marking.id);
  const std::size_t fingerprint = GeometryFingerprint(marking);
  if (Unchanged(kMarkingNs, kLabelNs, id, fingerprint, mode)) return;
  const std_msgs::ColorRGBA color = ClassColor(marking.class_id, marking.class_name);
  Marker outline = NewMarker(kNamespaces[kMarkingNs], id, Marker::LINE_STRIP, frame_id, stamp);
  outline.scale.x = 0.08;
  outline.color = color;
  for (int i = 0; i <= 4; ++i) outline.points.push_back(ToPointMsg(marking.corners_map[i % 4]));
  Add(kMarkingNs, fingerprint, std::move(outline), out);
  Marker label = NewMarker(kNamespaces[kLabelNs], id, Marker::TEXT_VIEW_FACING, frame_id, stamp);
  label.pose.position = ToPointMsg(marking.Center() + Eigen::Vector3d(0.0, 0.0, 0.5));
  label.scale.z = 0.6;  // text height, m
  label.color = color;
  label.text =
      marking.class_name.empty() ? "class " + std::to_string(marking.class_id) : marking.class_name;
  Add(kLabelNs, fingerprint, std::move(label), out);
}

void MarkerBuilder::DeleteIfStale(std::uint64_t key, const std::string& frame_id,
                                  const ros::Time& stamp, visualization_msgs::MarkerArray* out) {
  const auto it = published_.find(key);
  if (it == published_.end() || it->second.generation == generation_) return;
  visualization_msgs::Marker gone =
      NewMarker(kNamespaces[key >> 32], static_cast<int>(key & 0xffffffffu),
                visualization_msgs::Marker::LINE_STRIP, frame_id, stamp);
  gone.action = visualization_msgs::Marker::DELETE;
  out->markers.push_back(gone);
  published_.erase(it);
}

visualization_msgs::MarkerArray MarkerBuilder::Build(const VectorMap& map,
                                                     const std::string& frame_id,
                                                     const ros::Time& stamp, Mode mode) {
  visualization_msgs::MarkerArray out;
  ++generation_;
  work_ = Work();
  lane_chunks_.clear();
  for (const MapLane& lane : map.lanes) AddLane(lane, 0, 0, frame_id, stamp, mode, &out);
  for (const MapMarking& marking : map.markings) AddMarking(marking, frame_id, stamp, mode, &out);
  // What this map no longer draws: deleted on screen and forgotten.
  std::vector<std::uint64_t> stale;
  for (const auto& [key, sent] : published_) {
    if (sent.generation != generation_) stale.push_back(key);
  }
  for (std::uint64_t key : stale) DeleteIfStale(key, frame_id, stamp, &out);
  return out;
}

visualization_msgs::MarkerArray MarkerBuilder::Build(const MapChanges& changes,
                                                     const std::string& frame_id,
                                                     const ros::Time& stamp) {
  if (changes.complete) return Build(changes.map, frame_id, stamp, Mode::kChanges);
  visualization_msgs::MarkerArray out;
  ++generation_;
  work_ = Work();
  for (std::size_t i = 0; i < changes.map.lanes.size(); ++i) {
    const MapLane& lane = changes.map.lanes[i];
    // Without the core's ranges (a hand-made MapChanges): the whole lane.
    const std::size_t offset = i < changes.lane_offsets.size() ? changes.lane_offsets[i] : 0;
    const std::size_t first_chunk =
        AddLane(lane, i < changes.lane_first_changed.size() ? changes.lane_first_changed[i] : 0,
                offset, frame_id, stamp, Mode::kChanges, &out);
    // The chunks it drew before and does not draw now (it lost points, or a chunk's curve
    // could not be drawn), of those it looked at.
    for (std::size_t chunk = first_chunk; chunk < lane_chunks_[lane.id]; ++chunk) {
      const int id = LaneChunkMarkerId(lane.id, chunk);
      for (const std::size_t ns : {kLaneNs, kControlPointNs}) {
        DeleteIfStale(Key(ns, id), frame_id, stamp, &out);
      }
    }
    lane_chunks_[lane.id] =
        LaneChunkCount(offset + lane.control_points_map.size(), lane_chunk_segments_);
  }
  for (const MapMarking& marking : changes.map.markings) {
    AddMarking(marking, frame_id, stamp, Mode::kChanges, &out);
  }
  for (std::uint64_t lane_id : changes.removed_lane_ids) {
    const auto it = lane_chunks_.find(lane_id);
    if (it == lane_chunks_.end()) continue;
    for (std::size_t chunk = 0; chunk < it->second; ++chunk) {
      const int id = LaneChunkMarkerId(lane_id, chunk);
      for (const std::size_t ns : {kLaneNs, kControlPointNs}) {
        DeleteIfStale(Key(ns, id), frame_id, stamp, &out);
      }
    }
    lane_chunks_.erase(it);
  }
  for (std::uint64_t marking_id : changes.removed_marking_ids) {
    const int id = MarkerId(marking_id);
    for (const std::size_t ns : {kMarkingNs, kLabelNs}) {
      DeleteIfStale(Key(ns, id), frame_id, stamp, &out);
    }
  }
  return out;
}

visualization_msgs::MarkerArray MarkerBuilder::Clear() {
  visualization_msgs::MarkerArray out;
  visualization_msgs::Marker all;
  all.action = visualization_msgs::Marker::DELETEALL;
  all.pose.orientation.w = 1.0;
  out.markers.push_back(all);
  published_.clear();
  lane_chunks_.clear();
  return out;
}

}  // namespace ipm_road_mapper
