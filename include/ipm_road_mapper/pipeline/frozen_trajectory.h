// The part of a live trajectory that no solve changes any more, kept as immutable,
// fixed-size chunks that successive map snapshots share (a snapshot copies the chunk
// pointers, not the poses), so that a snapshot's cost does not grow with the drive. The
// newest poses (those a window solve may still correct) stay in the snapshot's own map;
// FullTrajectory joins both for a save. No ROS header; not thread-safe (the mapping thread
// extends it; snapshots hold its immutable chunks).
#pragma once

#include <cstddef>
#include <memory>
#include <vector>

#include "ipm_road_mapper/core/geometry/rigid_transform.h"
#include "ipm_road_mapper/core/map/road_map.h"

namespace ipm_road_mapper {

// One immutable run of consecutive poses.
using TrajectoryChunk = std::vector<StampedPose>;
// The frozen prefix of a trajectory: chunks in order, shared between snapshots.
using TrajectoryChunks = std::vector<std::shared_ptr<const TrajectoryChunk>>;

class FrozenTrajectory {
 public:
  // `chunk_poses` poses per chunk (> 0).
  explicit FrozenTrajectory(std::size_t chunk_poses = 1000);

  // Freezes whole chunks of `frames` that lie before index `mutable_from` (the first frame a
  // solve may still change). Appends only: what was frozen is never re-read.
  void Extend(const std::vector<FrameRecord>& frames, std::size_t mutable_from);

  // The frozen chunks (copy the vector to share them).
  const TrajectoryChunks& chunks() const { return chunks_; }
  // Poses frozen so far: the index of the first pose not in a chunk.
  std::size_t size() const { return size_; }

  // Forgets every chunk (after a ~reset).
  void Clear();

 private:
  std::size_t chunk_poses_;
  TrajectoryChunks chunks_;
  std::size_t size_ = 0;
};

// The whole trajectory: every pose of `prefix`, then `tail`.
std::vector<StampedPose> FullTrajectory(const TrajectoryChunks& prefix,
                                        const std::vector<StampedPose>& tail);

}  // namespace ipm_road_mapper
