#include "ipm_road_mapper/ros/vector_map_delta_builder.h"

#include <algorithm>
#include <functional>
#include <stdexcept>
#include <string>
#include <unordered_set>
#include <utility>

#include "ipm_road_mapper/ros/element_fingerprint.h"
#include "ipm_road_mapper/ros/msg_conversion.h"
#include "ipm_road_mapper/ros/vector_map_conversion.h"

namespace ipm_road_mapper {
namespace {

// Erases the entries `generation` did not see and returns their ids, sorted (the elements
// that left the map).
template <typename Sent>
std::vector<std::uint64_t> EraseUnseen(std::unordered_map<std::uint64_t, Sent>* sent,
                                       std::uint64_t generation) {
  std::vector<std::uint64_t> gone;
  for (auto it = sent->begin(); it != sent->end();) {
    if (it->second.generation == generation) {
      ++it;
      continue;
    }
    gone.push_back(it->first);
    it = sent->erase(it);
  }
  std::sort(gone.begin(), gone.end());
  return gone;
}

}  // namespace

VectorMapDeltaBuilder::VectorMapDeltaBuilder(std::size_t lane_chunk_points)
    : lane_chunk_points_(std::max<std::size_t>(lane_chunk_points, 1)) {}

ipm_road_mapper::VectorMapDelta VectorMapDeltaBuilder::NewDelta(const std::string& frame_id,
                                                                const ros::Time& stamp) {
  ipm_road_mapper::VectorMapDelta delta;
  delta.header.frame_id = frame_id;
  delta.header.stamp = stamp;
  delta.sequence = ++sequence_;
  delta.base_to_camera.rotation.w = 1.0;
  return delta;
}

void VectorMapDeltaBuilder::AddMarking(const MapMarking& marking,
                                       ipm_road_mapper::VectorMapDelta* delta) {
  const std::size_t fingerprint = MessageFingerprint(marking);
  const auto [it, added] = markings_.try_emplace(marking.id);
  if (added || it->second.fingerprint != fingerprint) {
    delta->markings.push_back(ToMarkingMsg(marking));
  }
  it->second = {fingerprint, generation_};
}

void VectorMapDeltaBuilder::AddLane(const MapLane& lane, std::size_t first_changed,
                                    std::size_t offset, ipm_road_mapper::VectorMapDelta* delta) {
  const std::size_t points = offset + lane.control_points_map.size();
  const std::size_t chunks = (points + lane_chunk_points_ - 1) / lane_chunk_points_;
  const auto [it, added] = lanes_.try_emplace(lane.id);
  LaneSent& sent = it->second;
  // The chunks before the one the first changed point falls in are as sent.
  const std::size_t kept =
      added ? 0 : std::min({first_changed / lane_chunk_points_, sent.chunks.size(), chunks});
  if (kept * lane_chunk_points_ < offset) {
    throw std::invalid_argument("VectorMapDeltaBuilder: lane " + std::to_string(lane.id) +
                                " came without the points its first changed chunk needs");
  }
  // The first chunk that differs from what was sent: the points before it are as sent.
  std::size_t first = added ? 0 : points;
  for (std::size_t chunk = kept; chunk < chunks; ++chunk) {
    const std::size_t begin = chunk * lane_chunk_points_;
    const std::size_t end = std::min(begin + lane_chunk_points_, points);
    const std::size_t fingerprint = GeometryFingerprint(lane, begin - offset, end - offset);
    work_.points_fingerprinted += end - begin;
    if (chunk >= sent.chunks.size()) {
      sent.chunks.push_back(fingerprint);
      first = std::min(first, begin);
    } else if (sent.chunks[chunk] != fingerprint) {
      sent.chunks[chunk] = fingerprint;
      first = std::min(first, begin);
    }
  }
  sent.chunks.resize(chunks);
  const std::size_t fields = FieldsFingerprint(lane);
  if (first < points || points != sent.points || fields != sent.fields || added) {
    delta->lanes.push_back(ToLanePatchMsg(lane, first - offset));
    delta->lanes.back().first_index = static_cast<std::uint32_t>(first);
    work_.points_converted += points - first;
  }
  sent.fields = fields;
  sent.points = points;
  sent.generation = generation_;
}

ipm_road_mapper::VectorMapDelta VectorMapDeltaBuilder::Build(const VectorMap& map,
                                                             const std::string& frame_id,
                                                             const ros::Time& stamp) {
  ipm_road_mapper::VectorMapDelta delta = NewDelta(frame_id, stamp);
  ++generation_;
  work_ = Work();
  for (const MapMarking& marking : map.markings) AddMarking(marking, &delta);
  for (const MapLane& lane : map.lanes) AddLane(lane, 0, 0, &delta);
  delta.removed_marking_ids = EraseUnseen(&markings_, generation_);
  delta.removed_lane_ids = EraseUnseen(&lanes_, generation_);
  delta.base_to_camera = IsometryToTransform(map.T_base_cam);
  return delta;
}

ipm_road_mapper::VectorMapDelta VectorMapDeltaBuilder::Build(const MapChanges& changes,
                                                             const std::string& frame_id,
                                                             const ros::Time& stamp) {
  if (changes.complete) return Build(changes.map, frame_id, stamp);
  ipm_road_mapper::VectorMapDelta delta = NewDelta(frame_id, stamp);
  ++generation_;
  work_ = Work();
  for (const MapMarking& marking : changes.map.markings) AddMarking(marking, &delta);
  for (std::size_t i = 0; i < changes.map.lanes.size(); ++i) {
    // Without the core's ranges (a hand-made MapChanges): the whole lane.
    const std::size_t first_changed =
        i < changes.lane_first_changed.size() ? changes.lane_first_changed[i] : 0;
    const std::size_t offset = i < changes.lane_offsets.size() ? changes.lane_offsets[i] : 0;
    AddLane(changes.map.lanes[i], first_changed, offset, &delta);
  }
  // What left the map, of what was sent (the ids come sorted).
  for (std::uint64_t id : changes.removed_marking_ids) {
    if (markings_.erase(id)) delta.removed_marking_ids.push_back(id);
  }
  for (std::uint64_t id : changes.removed_lane_ids) {
    if (lanes_.erase(id)) delta.removed_lane_ids.push_back(id);
  }
  delta.base_to_camera = IsometryToTransform(changes.map.T_base_cam);
  return delta;
}

ipm_road_mapper::VectorMapDelta VectorMapDeltaBuilder::Clear(const std::string& frame_id,
                                                             const ros::Time& stamp) {
  ipm_road_mapper::VectorMapDelta delta = NewDelta(frame_id, stamp);
  delta.reset = true;
  markings_.clear();
  lanes_.clear();
  return delta;
}

void ApplyVectorMapDelta(const ipm_road_mapper::VectorMapDelta& delta, VectorMap* map) {
  if (delta.reset) {
    map->markings.clear();
    map->lanes.clear();
  }
  map->frame_id = delta.header.frame_id;
  const std::unordered_set<std::uint64_t> gone_markings(delta.removed_marking_ids.begin(),
                                                        delta.removed_marking_ids.end());
  const std::unordered_set<std::uint64_t> gone_lanes(delta.removed_lane_ids.begin(),
                                                     delta.removed_lane_ids.end());
  auto& markings = map->markings;
  markings.erase(std::remove_if(markings.begin(), markings.end(),
                                [&](const MapMarking& m) { return gone_markings.count(m.id); }),
                 markings.end());
  auto& lanes = map->lanes;
  lanes.erase(std::remove_if(lanes.begin(), lanes.end(),
                             [&](const MapLane& l) { return gone_lanes.count(l.id); }),
              lanes.end());
  std::unordered_map<std::uint64_t, std::size_t> marking_at, lane_at;
  for (std::size_t i = 0; i < markings.size(); ++i) marking_at[markings[i].id] = i;
  for (std::size_t i = 0; i < lanes.size(); ++i) lane_at[lanes[i].id] = i;
  for (const auto& m : delta.markings) {
    ipm_road_mapper::VectorMapMsg one;
    one.markings.push_back(m);
    const MapMarking marking = FromVectorMapMsg(one).markings.front();
    const auto it = marking_at.find(m.id);
    if (it == marking_at.end()) {
      marking_at[m.id] = markings.size();
      markings.push_back(marking);
    } else {
      markings[it->second] = marking;
    }
  }
  for (const auto& patch : delta.lanes) {
    auto it = lane_at.find(patch.id);
    if (it == lane_at.end()) {
      it = lane_at.emplace(patch.id, lanes.size()).first;
      lanes.emplace_back();
      lanes.back().id = patch.id;
    }
    MapLane& lane = lanes[it->second];
    lane.class_id = patch.class_id;
    lane.class_name = patch.class_name;
    lane.style = patch.style == "unknown" ? "" : patch.style;
    const std::size_t keep =
        std::min<std::size_t>(patch.first_index, lane.control_points_map.size());
    lane.control_points_map.resize(keep);
    for (const auto& p : patch.control_points) lane.control_points_map.push_back(FromPointMsg(p));
    // The unmeasured flags of the points kept, then the patch's (none when it has none).
    SetUnmeasuredFlags(patch.unmeasured.size() == patch.control_points.size()
                           ? patch.unmeasured
                           : std::vector<std::uint8_t>(),
                       keep, &lane);
    lane.observations = patch.observations;
    lane.first_seen = ToSeconds(patch.first_seen);
    lane.last_seen = ToSeconds(patch.last_seen);
    lane.predecessors = patch.predecessors;
    lane.successors = patch.successors;
  }
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  if (TransformToIsometry(delta.base_to_camera, &T).empty()) map->T_base_cam = T;
}

}  // namespace ipm_road_mapper
