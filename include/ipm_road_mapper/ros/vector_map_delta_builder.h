// Builds ~vector_map_delta messages (msg/VectorMapDelta.msg): the markings of a map that are
// new or changed since the previous delta, the changed end of each new or changed lane
// (LaneSplinePatch), and the ids of the elements that left the map. It remembers a
// fingerprint per marking and per chunk of each lane's control points, so a message
// carries what changed, not the whole map: retired markings, which no solve moves any
// more, are sent once; a lane that grows sends its last chunk or two. Built from the core's
// incremental export (MapChanges), it looks at the changed elements only, and of a changed
// lane at its chunks from the one its first changed control point falls in (the earlier
// ones are kept as sent; the core's changes may carry the lane's tail only): its cost
// follows what changed, not the map's length; the message is the one Build(VectorMap)
// would make.
#pragma once

#include <ros/time.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

#include "ipm_road_mapper/VectorMapDelta.h"
#include "ipm_road_mapper/core/map/vector_map.h"
#include "ipm_road_mapper/core/mapper/map_changes.h"

namespace ipm_road_mapper {

class VectorMapDeltaBuilder {
 public:
  // Lane control points are compared in chunks of `lane_chunk_points` (> 0).
  explicit VectorMapDeltaBuilder(std::size_t lane_chunk_points = 16);

  // The delta from the previous call's map to `map`, in `frame_id` at `stamp` (the first
  // call: every element).
  ipm_road_mapper::VectorMapDelta Build(const VectorMap& map, const std::string& frame_id,
                                        const ros::Time& stamp);

  // The same delta from the core's changes since the previous call's map (its revision or
  // an older one): only the changed elements are compared; a complete `changes` (the first
  // export, after a reset) is Build(changes.map).
  ipm_road_mapper::VectorMapDelta Build(const MapChanges& changes, const std::string& frame_id,
                                        const ros::Time& stamp);

  // A delta with `reset` set and nothing else (after ~reset); forgets every element.
  ipm_road_mapper::VectorMapDelta Clear(const std::string& frame_id, const ros::Time& stamp);

  // The control points a changed lane's tail must carry before its first changed one
  // (ChangesOptions::lane_context_points): the start of that point's chunk. Build throws
  // std::invalid_argument on a tail that starts later, or on a tail of a lane it never sent.
  std::size_t lane_context_points() const { return lane_chunk_points_ - 1; }

  // What the last Build looked at: lane control points fingerprinted and converted into
  // patches (their cost; a lane that changed at its end costs about its last chunks).
  struct Work {
    std::size_t points_fingerprinted = 0;
    std::size_t points_converted = 0;
  };
  const Work& last_work() const { return work_; }

 private:
  // What was sent of one marking, and the last Build whose map held it.
  struct MarkingSent {
    std::size_t fingerprint = 0;  // MessageFingerprint
    std::uint64_t generation = 0;
  };
  // What was sent of one lane, and the last Build whose map held it.
  struct LaneSent {
    std::size_t fields = 0;           // MessageFingerprint without the control points
    std::vector<std::size_t> chunks;  // fingerprint per chunk of control points
    std::size_t points = 0;
    std::uint64_t generation = 0;
  };
  // Adds `marking` to `delta` when new or changed, and remembers it as of this generation.
  void AddMarking(const MapMarking& marking, ipm_road_mapper::VectorMapDelta* delta);
  // Adds `lane`'s patch from its first changed chunk, when new or changed, and remembers it.
  // `lane` holds the whole lane's points from `offset` on; the whole lane's points before
  // `first_changed` are as sent (0, 0: a whole lane, every chunk compared).
  void AddLane(const MapLane& lane, std::size_t first_changed, std::size_t offset,
               ipm_road_mapper::VectorMapDelta* delta);
  ipm_road_mapper::VectorMapDelta NewDelta(const std::string& frame_id, const ros::Time& stamp);

  std::size_t lane_chunk_points_;
  std::uint32_t sequence_ = 0;
  std::uint64_t generation_ = 0;  // Build calls so far
  std::unordered_map<std::uint64_t, MarkingSent> markings_;
  std::unordered_map<std::uint64_t, LaneSent> lanes_;
  Work work_;
};

// Applies `delta` to `map` (a client's copy, started from a ~vector_map): what a subscriber
// of both topics does. Lane patches whose first_index is past the lane's points are applied
// at its end.
void ApplyVectorMapDelta(const ipm_road_mapper::VectorMapDelta& delta, VectorMap* map);

}  // namespace ipm_road_mapper
