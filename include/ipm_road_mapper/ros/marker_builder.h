// The map as rviz markers (visualization_msgs/MarkerArray):
// - namespace "lanes": each lane spline sampled every 0.5 m, as one LINE_STRIP per chunk of
//   `lane_chunk_segments` spline segments (consecutive chunks share their end sample);
// - "lane_control_points": the chunk's control points (phantom ends included) as a
//   SPHERE_LIST with the chunk's id;
// - "markings": each marking's 4 corners as a closed LINE_STRIP;
// - "marking_labels": its class name as TEXT_VIEW_FACING above its center.
// Colors by class (ClassColor). The builder remembers what it published, with a fingerprint
// of each element's class and geometry: an element that left the map (a merged lane, a
// dropped spurious marking, a reset) gets a DELETE, so rviz never shows stale markers, and
// in kChanges mode an element whose fingerprint did not change is not built nor sent again
// (the per-publish cost then follows what changed, not the map's length): a lane that grows
// at its end re-sends its last chunk or two, not the whole lane. Built from the core's
// incremental export (MapChanges), it looks at the changed and removed elements only, and of
// a changed lane at the chunks whose curve uses its first changed control point or a later
// one (the core's changes may carry the lane's tail only). The
// markers are those of kChanges on the whole map (the DELETEs may come in another order).
// Marking marker ids are
// the element ids (mod 2^31); lane chunk ids are LaneChunkMarkerId; both stable over the
// element's life.
#pragma once

#include <ros/time.h>
#include <std_msgs/ColorRGBA.h>
#include <visualization_msgs/MarkerArray.h>

#include <cstddef>
#include <cstdint>
#include <set>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "ipm_road_mapper/core/map/vector_map.h"
#include "ipm_road_mapper/core/mapper/map_changes.h"

namespace ipm_road_mapper {

// A fixed, distinct color per class: lane classes named "*yellow*" are yellow, "*white*"
// white; every other class gets a color of a 12-color palette picked by its id.
std_msgs::ColorRGBA ClassColor(int class_id, const std::string& class_name);

// The marker id of chunk `chunk` of lane `lane_id`: the lane id's low 21 bits, then the
// chunk's low 10 bits (unique for lanes of up to 1024 chunks, ids below 2^21).
int LaneChunkMarkerId(std::uint64_t lane_id, std::size_t chunk);

// One chunk of a lane's markers, as control-point index ranges.
struct LaneChunk {
  std::size_t index = 0;                          // 0 = the chunk at the lane's start
  std::size_t curve_first = 0, curve_last = 0;    // [first, last): the points its curve uses
  std::size_t points_first = 0, points_last = 0;  // [first, last): the points it draws
};

// How a lane of `control_points` points is cut into chunks of `chunk_segments` segments
// (the last may be shorter; one chunk of every point when there is no spline, < 4 points).
std::vector<LaneChunk> LaneChunks(std::size_t control_points, std::size_t chunk_segments);
// How many chunks LaneChunks gives, and its chunk `index` (< that count), without the others.
std::size_t LaneChunkCount(std::size_t control_points, std::size_t chunk_segments);
LaneChunk LaneChunkAt(std::size_t control_points, std::size_t chunk_segments, std::size_t index);

// Builds MarkerArrays of successive maps, with DELETEs for what disappeared.
class MarkerBuilder {
 public:
  // Lane samples every `lane_sample_spacing_m` of arc length; lane markers in chunks of
  // `lane_chunk_segments` spline segments.
  explicit MarkerBuilder(double lane_sample_spacing_m = 0.5, std::size_t lane_chunk_segments = 16);

  // kFull: every element's markers; kChanges: only those of elements that are new or whose
  // class or geometry changed since they were last sent.
  enum class Mode { kFull, kChanges };

  // The markers of `map` in `frame_id` at `stamp` (all of them, or the changes), plus a
  // DELETE for every marker of the previous calls that is not in this map.
  visualization_msgs::MarkerArray Build(const VectorMap& map, const std::string& frame_id,
                                        const ros::Time& stamp, Mode mode = Mode::kFull);

  // kChanges from the core's changes since the previous call's map (its revision or an
  // older one): the markers of the changed elements whose class or geometry changed, and
  // DELETEs for the removed elements' markers and a changed lane's vanished chunks. A
  // complete `changes` is Build(changes.map, kChanges).
  visualization_msgs::MarkerArray Build(const MapChanges& changes, const std::string& frame_id,
                                        const ros::Time& stamp);

  // One DELETEALL marker (after ~reset); forgets what was published.
  visualization_msgs::MarkerArray Clear();

  // The control points a changed lane's tail must carry before its first changed one
  // (ChangesOptions::lane_context_points): the curve of the first chunk that uses it starts
  // up to a chunk and 3 points before it. Build throws std::invalid_argument on a tail that
  // starts later.
  std::size_t lane_context_points() const { return lane_chunk_segments_ + 2; }

  // What the last Build looked at: lane control points fingerprinted, and those of the lane
  // chunks it drew (their cost; a lane that changed at its end costs about its last chunks).
  struct Work {
    std::size_t points_fingerprinted = 0;
    std::size_t points_drawn = 0;
  };
  const Work& last_work() const { return work_; }

 private:
  // What was sent of one marker: its element's fingerprint, and the last Build that drew it.
  struct Sent {
    std::size_t fingerprint = 0;
    std::uint64_t generation = 0;
  };
  // Adds the markers of `lane` (of `marking`) that are not unchanged in kChanges mode. `lane`
  // holds the whole lane's points from `offset` on, and the chunks whose curve ends at or
  // before `first_changed` are as drawn (0, 0: a whole lane, every chunk looked at). Returns
  // the first chunk it looked at.
  std::size_t AddLane(const MapLane& lane, std::size_t first_changed, std::size_t offset,
                      const std::string& frame_id, const ros::Time& stamp, Mode mode,
                      visualization_msgs::MarkerArray* out);
  void AddMarking(const MapMarking& marking, const std::string& frame_id, const ros::Time& stamp,
                  Mode mode, visualization_msgs::MarkerArray* out);
  // Records `marker` as published now with `fingerprint` and appends it to *out.
  void Add(std::size_t ns, std::size_t fingerprint, visualization_msgs::Marker marker,
           visualization_msgs::MarkerArray* out);
  // kChanges: true (and the markers kept as of this Build) when an element drawn before
  // under namespaces ns_a / ns_b and `id` has the same fingerprint.
  bool Unchanged(std::size_t ns_a, std::size_t ns_b, int id, std::size_t fingerprint, Mode mode);
  // DELETEs the marker `key` when published but not drawn by this Build.
  void DeleteIfStale(std::uint64_t key, const std::string& frame_id, const ros::Time& stamp,
                     visualization_msgs::MarkerArray* out);

  double lane_sample_spacing_m_;
  std::size_t lane_chunk_segments_;
  // Every marker on screen now, by (namespace index << 32 | id).
  std::unordered_map<std::uint64_t, Sent> published_;
  std::uint64_t generation_ = 0;  // Build calls so far
  // Chunks drawn of each lane (the incremental build deletes the ones a lane lost).
  std::unordered_map<std::uint64_t, std::size_t> lane_chunks_;
  Work work_;
};

}  // namespace ipm_road_mapper
