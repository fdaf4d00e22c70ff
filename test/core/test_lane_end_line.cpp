// FitLaneEndLine: the last chord's line with two points, a line through the lane's last
// stretch with more, at either end; DistanceFromEndLine's distance and reach.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "ipm_road_mapper/core/geometry/catmull_rom_spline.h"
#include "ipm_road_mapper/core/geometry/lane_end_line.h"

namespace ipm_road_mapper {
namespace {

// Control points every 3 m along y = 0 from x = 0 to 30, phantom ends included, the last
// real one moved `curl` m across.
std::vector<Eigen::Vector3d> CurledLane(double curl) {
  std::vector<Eigen::Vector3d> cps;
  for (double x = -3.0; x <= 33.0 + 1e-9; x += 3.0) cps.emplace_back(x, 0.0, 0.0);
  const std::size_t n = cps.size();
  cps[n - 2].y() = curl;
  cps[n - 1] = 2.0 * cps[n - 2] - cps[n - 3];
  return cps;
}

TEST(FitLaneEndLine, WithTwoPointsItIsTheSplinesEndTangent) {
  const std::vector<Eigen::Vector3d> cps = CurledLane(0.5);
  const LaneEndLine line = FitLaneEndLine(cps, true, 1.0);
  ASSERT_TRUE(line.valid);
  const CatmullRomSpline spline(cps);
  const Eigen::Vector2d tangent =
      spline.Derivative(static_cast<double>(spline.NumSegments())).head<2>().normalized();
  EXPECT_NEAR(line.Direction().dot(tangent), 1.0, 1e-12);
  EXPECT_NEAR((line.origin - Eigen::Vector2d(30.0, 0.5)).norm(), 0.0, 1e-12);
  // 12 m past the end, the chord's line is 2 m across: 0.5 + 12 * 0.5 / 3.
  double along = 0.0;
  EXPECT_NEAR(DistanceFromEndLine(line, Eigen::Vector3d(42.0, 2.5, 0.0), &along), 0.0, 1e-9);
  EXPECT_NEAR(along, std::hypot(12.0, 2.0), 1e-9);
}

TEST(FitLaneEndLine, OverTheLastStretchTheEndsCurlMovesItLittle) {
  const LaneEndLine line = FitLaneEndLine(CurledLane(0.5), true, 15.0);  // 6 points
  ASSERT_TRUE(line.valid);
  // Least squares over x = 15..30 with one point 0.5 m off: at 12 m past the end the line is
  // within 0.8 m of the lane (the last chord's: 2.5 m).
  double along = 0.0;
  EXPECT_LT(DistanceFromEndLine(line, Eigen::Vector3d(42.0, 0.0, 0.0), &along), 0.8);
  EXPECT_NEAR(along, 12.0, 0.1);
  EXPECT_GT(DistanceFromEndLine(line, Eigen::Vector3d(42.0, 3.5, 0.0), nullptr), 2.5);
  // A straight lane: exactly its line.
  const LaneEndLine straight = FitLaneEndLine(CurledLane(0.0), true, 15.0);
  EXPECT_NEAR(DistanceFromEndLine(straight, Eigen::Vector3d(45.0, 0.0, 0.0), nullptr), 0.0, 1e-12);
  EXPECT_NEAR(DistanceFromEndLine(straight, Eigen::Vector3d(45.0, -1.5, 0.0), nullptr), 1.5, 1e-12);
}

TEST(FitLaneEndLine, AtTheStartItLooksBackward) {
  std::vector<Eigen::Vector3d> cps = CurledLane(0.0);
  cps[1].y() = -0.5;  // the first real point curled, its phantom with it
  cps[0] = 2.0 * cps[1] - cps[2];
  const LaneEndLine line = FitLaneEndLine(cps, false, 15.0);
  ASSERT_TRUE(line.valid);
  EXPECT_LT(line.forward.x(), -0.99);  // outward: toward -x
  double along = 0.0;
  EXPECT_LT(DistanceFromEndLine(line, Eigen::Vector3d(-12.0, 0.0, 0.0), &along), 0.8);
  EXPECT_NEAR(along, 12.0, 0.1);
}

TEST(FitLaneEndLine, InvalidWithoutTwoRealFinitePoints) {
  EXPECT_FALSE(
      FitLaneEndLine({Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX(), Eigen::Vector3d(2, 0, 0)},
                     true, 15.0)
          .valid);
  std::vector<Eigen::Vector3d> cps = CurledLane(0.0);
  cps[cps.size() - 3].x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(FitLaneEndLine(cps, true, 15.0).valid);
  // Two coincident points: no direction.
  EXPECT_FALSE(FitLaneEndLine({Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                               Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()},
                              true, 15.0)
                   .valid);
}

}  // namespace
}  // namespace ipm_road_mapper
