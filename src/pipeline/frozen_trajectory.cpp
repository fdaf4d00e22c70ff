#include "ipm_road_mapper/pipeline/frozen_trajectory.h"

#include <algorithm>

namespace ipm_road_mapper {

FrozenTrajectory::FrozenTrajectory(std::size_t chunk_poses)
    : chunk_poses_(std::max<std::size_t>(chunk_poses, 1)) {}

void FrozenTrajectory::Extend(const std::vector<FrameRecord>& frames, std::size_t mutable_from) {
  const std::size_t limit = std::min(mutable_from, frames.size());
  while (size_ + chunk_poses_ <= limit) {
    auto chunk = std::make_shared<TrajectoryChunk>();
    chunk->reserve(chunk_poses_);
    for (std::size_t i = size_; i < size_ + chunk_poses_; ++i) {
      chunk->push_back({frames[i].stamp, frames[i].T_map_base});
    }
    chunks_.push_back(std::move(chunk));
    size_ += chunk_poses_;
  }
}

void FrozenTrajectory::Clear() {
  chunks_.clear();
  size_ = 0;
}

std::vector<StampedPose> FullTrajectory(const TrajectoryChunks& prefix,
                                        const std::vector<StampedPose>& tail) {
  std::size_t total = tail.size();
  for (const auto& chunk : prefix) total += chunk->size();
  std::vector<StampedPose> out;
  out.reserve(total);
  for (const auto& chunk : prefix) out.insert(out.end(), chunk->begin(), chunk->end());
  out.insert(out.end(), tail.begin(), tail.end());
  return out;
}

}  // namespace ipm_road_mapper
