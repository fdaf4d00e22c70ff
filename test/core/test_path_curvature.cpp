// PathCurvature and the concentric curvature of lines beside the path (path_curvature.h): a
// vehicle on an R 30 m arc reads 1/30, a line 1.75 m inside it 1/28.25 and one outside
// 1/31.75, signed by the lane's direction; straight, short and crossing cases read 0.
#include <gtest/gtest.h>

#include <cmath>

#include "ipm_road_mapper/core/mapper/path_curvature.h"

namespace ipm_road_mapper {
namespace {

// Frames every 0.5 m along a circle of radius R from the origin heading +x (side +1: left
// turn, -1: right, 0: straight), `count` of them.
std::vector<FrameRecord> ArcFrames(double R, double side, std::size_t count) {
  std::vector<FrameRecord> frames;
  for (std::size_t k = 0; k < count; ++k) {
    const double s = 0.5 * static_cast<double>(k);
    FrameRecord f;
    f.index = k;
    if (side == 0.0) {
      f.T_map_base.translation() = Eigen::Vector3d(s, 0.0, 0.0);
    } else {
      const double a = s / R;
      f.T_map_base.translation() =
          Eigen::Vector3d(R * std::sin(a), side * R * (1.0 - std::cos(a)), 0.0);
      f.T_map_base.linear() = Eigen::AngleAxisd(side * a, Eigen::Vector3d::UnitZ()).matrix();
    }
    frames.push_back(f);
  }
  return frames;
}

TEST(PathCurvature, ReadsTheArcsCurvatureAndZeroWhenStraightOrShort) {
  const double R = 30.0;
  EXPECT_NEAR(PathCurvature(ArcFrames(R, 1.0, 60), 59, 10.0), 1.0 / R, 1e-3);
  EXPECT_NEAR(PathCurvature(ArcFrames(R, -1.0, 60), 59, 10.0), -1.0 / R, 1e-3);
  EXPECT_EQ(PathCurvature(ArcFrames(R, 0.0, 60), 59, 10.0), 0.0);
  EXPECT_EQ(PathCurvature(ArcFrames(R, 1.0, 8), 7, 10.0), 0.0);   // 3.5 m driven so far
  EXPECT_EQ(PathCurvature(ArcFrames(R, 1.0, 60), 59, 0.0), 0.0);  // switched off
}

// After a long stop the chord would reach back to the curve driven before it: no curvature
// is read from more than 20 s back, and the walk does not go through the whole stop.
TEST(PathCurvature, ALongStandstillAfterAnArcReadsNoCurvature) {
  std::vector<FrameRecord> frames = ArcFrames(30.0, 1.0, 60);
  for (std::size_t k = 0; k < frames.size(); ++k) frames[k].stamp = 0.05 * static_cast<double>(k);
  EXPECT_NEAR(PathCurvature(frames, 59, 10.0), 1.0 / 30.0, 1e-3);
  const FrameRecord last = frames.back();
  for (std::size_t k = 1; k <= 600; ++k) {  // 30 s standing still
    FrameRecord f = last;
    f.index = last.index + k;
    f.stamp = last.stamp + 0.05 * static_cast<double>(k);
    frames.push_back(f);
  }
  EXPECT_EQ(PathCurvature(frames, frames.size() - 1, 10.0), 0.0);
}

TEST(PathCurvature, LinesBesideTheArcTurnAboutItsCenter) {
  const double R = 30.0;
  for (const double side : {1.0, -1.0}) {
    const std::vector<FrameRecord> frames = ArcFrames(R, side, 60);
    const Eigen::Isometry3d& T = frames.back().T_map_base;
    const double kappa = PathCurvature(frames, 59, 10.0);
    // A point 10 m ahead and 1.75 m to the left of the vehicle, the lane heading along it.
    const Eigen::Vector3d forward = T.linear().col(0);
    const Eigen::Vector3d left_point = T * Eigen::Vector3d(10.0, 1.75, 0.0);
    const double radius_left = std::hypot(10.0, side * R - 1.75);
    EXPECT_NEAR(ConcentricCurvature(T, kappa, left_point, forward), side / radius_left, 2e-4);
    // The same lane ordered against the direction of travel turns the other way.
    EXPECT_NEAR(ConcentricCurvature(T, kappa, left_point, -forward), -side / radius_left, 2e-4);
    // A line across the path (a stop line) does not bend.
    EXPECT_EQ(ConcentricCurvature(T, kappa, left_point, T.linear().col(1)), 0.0);
  }
  // Inside the left turn the line is tighter than the path, outside it is wider.
  const std::vector<FrameRecord> frames = ArcFrames(R, 1.0, 60);
  const Eigen::Isometry3d& T = frames.back().T_map_base;
  const Eigen::Vector3d forward = T.linear().col(0);
  EXPECT_NEAR(ConcentricCurvature(T, 1.0 / R, T * Eigen::Vector3d(0, 1.75, 0), forward),
              1.0 / (R - 1.75), 1e-9);
  EXPECT_NEAR(ConcentricCurvature(T, 1.0 / R, T * Eigen::Vector3d(0, -1.75, 0), forward),
              1.0 / (R + 1.75), 1e-9);
}

TEST(PathCurvature, EndCurvaturesOfALaneAlongTheArc) {
  const double R = 30.0;
  const std::vector<FrameRecord> frames = ArcFrames(R, 1.0, 60);
  // A lane 1.75 m left of the path, control points every 3 m of the path from s = 15 to 45.
  std::vector<Eigen::Vector3d> cps;
  const double r = R - 1.75;
  for (double s = 12.0; s <= 48.0 + 1e-9; s += 3.0) {
    cps.emplace_back(r * std::sin(s / R), R - r * std::cos(s / R), 0.0);
  }
  const double min_curvature = MinGrowthCurvature(1.2, 15.0);
  EXPECT_NEAR(min_curvature, 1.0 / 93.75, 1e-9);
  const LaneEndCurvatures c = PathEndCurvatures(frames, 59, 10.0, min_curvature, cps);
  EXPECT_NEAR(c.at_start, 1.0 / r, 2e-3);
  EXPECT_NEAR(c.at_end, 1.0 / r, 2e-3);
  const LaneEndCurvatures off = PathEndCurvatures(frames, 59, 0.0, min_curvature, cps);
  EXPECT_EQ(off.at_start, 0.0);
  EXPECT_EQ(off.at_end, 0.0);
  // On an R 150 m curve the tangent keeps the line within the association gate: straight.
  std::vector<Eigen::Vector3d> gentle_cps;
  const double r150 = 150.0 - 1.75;
  for (double s = 12.0; s <= 48.0 + 1e-9; s += 3.0) {
    gentle_cps.emplace_back(r150 * std::sin(s / 150.0), 150.0 - r150 * std::cos(s / 150.0), 0.0);
  }
  const std::vector<FrameRecord> gentle_frames = ArcFrames(150.0, 1.0, 60);
  EXPECT_GT(std::abs(PathEndCurvatures(gentle_frames, 59, 10.0, 0.0, gentle_cps).at_end), 0.006);
  const LaneEndCurvatures gentle =
      PathEndCurvatures(gentle_frames, 59, 10.0, min_curvature, gentle_cps);
  EXPECT_EQ(gentle.at_start, 0.0);
  EXPECT_EQ(gentle.at_end, 0.0);
}

}  // namespace
}  // namespace ipm_road_mapper
