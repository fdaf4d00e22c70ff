// FrozenTrajectory: whole chunks frozen before the mutable tail, shared (not copied) by the
// snapshots, and joined with the tail into the whole trajectory.
#include <gtest/gtest.h>

#include "ipm_road_mapper/pipeline/frozen_trajectory.h"

namespace ipm_road_mapper {
namespace {

std::vector<FrameRecord> Frames(std::size_t n) {
  std::vector<FrameRecord> frames(n);
  for (std::size_t i = 0; i < n; ++i) {
    frames[i].index = i;
    frames[i].stamp = 0.05 * static_cast<double>(i);
    frames[i].T_map_base.translation() = Eigen::Vector3d(static_cast<double>(i), 0, 0);
  }
  return frames;
}

std::vector<StampedPose> Tail(const std::vector<FrameRecord>& frames, std::size_t from) {
  std::vector<StampedPose> tail;
  for (std::size_t i = from; i < frames.size(); ++i) {
    tail.push_back({frames[i].stamp, frames[i].T_map_base});
  }
  return tail;
}

TEST(FrozenTrajectory, FreezesWholeChunksBeforeTheMutableTail) {
  FrozenTrajectory frozen(10);
  std::vector<FrameRecord> frames = Frames(25);
  frozen.Extend(frames, 19);  // frames 19.. may still change: one chunk of 10 frozen
  EXPECT_EQ(frozen.size(), 10u);
  ASSERT_EQ(frozen.chunks().size(), 1u);
  const TrajectoryChunks shared = frozen.chunks();
  frames = Frames(40);
  frames[3].T_map_base.translation().y() = 5.0;  // a change to a frozen pose is not re-read
  frozen.Extend(frames, 30);
  EXPECT_EQ(frozen.size(), 30u);
  ASSERT_EQ(frozen.chunks().size(), 3u);
  EXPECT_EQ(frozen.chunks()[0].get(), shared[0].get());  // shared, not rebuilt
  EXPECT_DOUBLE_EQ(frozen.chunks()[0]->at(3).T_map_base.translation().y(), 0.0);
  // Frozen prefix + tail = the whole trajectory, in order.
  const std::vector<StampedPose> all = FullTrajectory(frozen.chunks(), Tail(frames, 30));
  ASSERT_EQ(all.size(), 40u);
  for (std::size_t i = 0; i < all.size(); ++i) {
    EXPECT_DOUBLE_EQ(all[i].T_map_base.translation().x(), static_cast<double>(i));
  }
  // mutable_from past the frames, or before what is frozen: nothing more, nothing less.
  frozen.Extend(frames, 1000);
  EXPECT_EQ(frozen.size(), 40u);
  frozen.Extend(frames, 5);
  EXPECT_EQ(frozen.size(), 40u);
  frozen.Clear();
  EXPECT_EQ(frozen.size(), 0u);
  EXPECT_TRUE(frozen.chunks().empty());
  EXPECT_EQ(FullTrajectory({}, Tail(frames, 38)).size(), 2u);
}

}  // namespace
}  // namespace ipm_road_mapper
