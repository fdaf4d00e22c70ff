// The frame index answers "within r" and "nearest" exactly as a scan over every frame does,
// also after frames move (pose corrections), across cell borders and far from the origin.
#include <gtest/gtest.h>

#include <limits>
#include <random>

#include "ipm_road_mapper/core/mapper/frame_index.h"

namespace ipm_road_mapper {
namespace {

std::vector<std::size_t> ScanWithin(const std::vector<Eigen::Vector3d>& p, const Eigen::Vector3d& q,
                                    double r) {
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if ((p[i] - q).head<2>().norm() <= r) out.push_back(i);
  }
  return out;
}

std::size_t ScanNearest(const std::vector<Eigen::Vector3d>& p, const Eigen::Vector3d& q) {
  double best = std::numeric_limits<double>::infinity();
  std::size_t index = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double d = (p[i] - q).head<2>().norm();
    if (d < best) {
      best = d;
      index = i;
    }
  }
  return index;
}

TEST(FrameIndex, AgreesWithAScanOverEveryFrame) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> xy(-200.0, 200.0), step(-3.0, 3.0);
  FrameIndex index(5.0);
  std::vector<Eigen::Vector3d> positions;
  for (std::size_t i = 0; i < 600; ++i) {
    positions.emplace_back(xy(rng), xy(rng), 0.0);
    index.Set(i, positions.back());
  }
  for (std::size_t i = 0; i < 600; i += 3) {  // corrections, some across cells
    positions[i] += Eigen::Vector3d(step(rng), step(rng), 0.0);
    index.Set(i, positions[i]);
  }
  ASSERT_EQ(index.size(), 600u);
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Vector3d q(1.5 * xy(rng), 1.5 * xy(rng), 0.0);  // also outside the cloud
    EXPECT_EQ(index.Within(q, 7.5), ScanWithin(positions, q, 7.5));
    std::size_t nearest = 0;
    double distance = 0.0;
    ASSERT_TRUE(index.Nearest(q, &nearest, &distance));
    EXPECT_EQ(nearest, ScanNearest(positions, q));
    EXPECT_DOUBLE_EQ(distance, (positions[nearest] - q).head<2>().norm());
  }
}

TEST(FrameIndex, NearestTiesGoToTheLowestIndexAndFarQueriesWork) {
  FrameIndex index(2.0);
  index.Set(0, Eigen::Vector3d(1.0e6, -1.0e6, 0.0));
  index.Set(1, Eigen::Vector3d(1.0e6 + 2.0, -1.0e6, 0.0));
  index.Set(2, Eigen::Vector3d(1.0e6 - 2.0, -1.0e6, 0.0));
  std::size_t nearest = 9;
  double distance = 0.0;
  ASSERT_TRUE(index.Nearest(Eigen::Vector3d(1.0e6, -1.0e6 + 2.0, 0.0), &nearest, &distance));
  EXPECT_EQ(nearest, 0u);
  ASSERT_TRUE(index.Nearest(Eigen::Vector3d(1.0e6 + 1.0, -1.0e6, 0.0), &nearest, &distance));
  EXPECT_EQ(nearest, 0u);  // 0 and 1 are both 1 m away
  EXPECT_TRUE(index.Within(Eigen::Vector3d::Zero(), 10.0).empty());
}

TEST(FrameIndex, EmptyAndBadUse) {
  FrameIndex index(1.0);
  std::size_t nearest = 0;
  double distance = 0.0;
  EXPECT_FALSE(index.Nearest(Eigen::Vector3d::Zero(), &nearest, &distance));
  EXPECT_TRUE(index.Within(Eigen::Vector3d::Zero(), 5.0).empty());
  EXPECT_THROW(index.Set(1, Eigen::Vector3d::Zero()), std::out_of_range);
  EXPECT_THROW(FrameIndex(0.0), std::invalid_argument);
  index.Set(0, Eigen::Vector3d::Zero());
  index.Clear();
  EXPECT_EQ(index.size(), 0u);
  EXPECT_FALSE(index.Nearest(Eigen::Vector3d::Zero(), &nearest, &distance));
}

}  // namespace
}  // namespace ipm_road_mapper
