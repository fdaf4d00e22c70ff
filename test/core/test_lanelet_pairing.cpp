// Lanelets from lane lines (lanelet_pairing.h): which lines bound one lane and where each
// line is cut, so that every lanelet has one piece of each bound; and the cases that must not
// make a lane (the two lines of a double line, lines too far apart, a line running the other
// way, a short overlap).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "ipm_road_mapper/core/geometry/grid_cell.h"
#include "ipm_road_mapper/core/map/lanelet_pairing.h"

namespace ipm_road_mapper {
namespace {

// A straight line at lateral offset y from x0 to x1 (samples every 0.5 m), along +x.
std::vector<Eigen::Vector3d> Straight(double y, double x0, double x1) {
  std::vector<Eigen::Vector3d> line;
  for (double x = x0; x <= x1 + 1e-9; x += 0.5) line.emplace_back(x, y, 0.0);
  return line;
}

// An arc of radius r (center (0, r): turning left) from angle 0 to `angle` at lateral
// offset y (radius r - y), samples every 0.5 m.
std::vector<Eigen::Vector3d> Arc(double r, double y, double angle) {
  const double radius = r - y;
  std::vector<Eigen::Vector3d> line;
  const int n = static_cast<int>(radius * angle / 0.5);
  for (int k = 0; k <= n; ++k) {
    const double a = angle * k / n;
    line.emplace_back(radius * std::sin(a), r - radius * std::cos(a), 0.0);
  }
  return line;
}

TEST(LaneletPairing, TwoParallelLinesAreOneLanelet) {
  const LaneletLayout layout = PairLanelets({Straight(0.0, 0, 100), Straight(3.5, 0, 100)});
  ASSERT_EQ(layout.lanelets.size(), 1u);
  EXPECT_EQ(layout.lanelets[0].right_line, 0u);  // y = 0 is right of y = 3.5 along +x
  EXPECT_EQ(layout.lanelets[0].left_line, 1u);
  EXPECT_TRUE(layout.cuts[0].empty());
  EXPECT_TRUE(layout.cuts[1].empty());
  EXPECT_EQ(layout.runs_left_out, 0u);
}

TEST(LaneletPairing, ThreeLinesAreTwoLaneletsSharingTheMiddleLine) {
  const LaneletLayout layout =
      PairLanelets({Straight(7.0, 0, 80), Straight(0.0, 0, 80), Straight(3.5, 0, 80)});
  ASSERT_EQ(layout.lanelets.size(), 2u);
  int shared = 0;
  for (const LaneletBounds& b : layout.lanelets) {
    if (b.left_line == 2 && b.right_line == 1) ++shared;
    if (b.left_line == 0 && b.right_line == 2) ++shared;
  }
  EXPECT_EQ(shared, 2);
}

TEST(LaneletPairing, ALaneThatStartsCutsItsNeighboursIntoPiecesThatCorrespond) {
  // A (y 0) and B (y 3.5) over 0-100 m; C (y 7) starts at 50 m: the lane A-B is cut at 50 m
  // (two lanelets, one after the other), the lane B-C uses B's second piece.
  const LaneletLayout layout =
      PairLanelets({Straight(0.0, 0, 100), Straight(3.5, 0, 100), Straight(7.0, 50, 100)});
  ASSERT_EQ(layout.cuts[0].size(), 1u);
  ASSERT_EQ(layout.cuts[1].size(), 1u);
  EXPECT_NEAR(layout.cuts[0][0], 50.0, 0.6);
  EXPECT_NEAR(layout.cuts[1][0], 50.0, 0.6);
  EXPECT_TRUE(layout.cuts[2].empty());
  ASSERT_EQ(layout.lanelets.size(), 3u);
  std::vector<std::pair<std::size_t, std::size_t>> ab, bc;  // (right piece, left piece)
  for (const LaneletBounds& b : layout.lanelets) {
    if (b.right_line == 0 && b.left_line == 1) ab.emplace_back(b.right_piece, b.left_piece);
    if (b.right_line == 1 && b.left_line == 2) bc.emplace_back(b.right_piece, b.left_piece);
  }
  ASSERT_EQ(ab.size(), 2u);
  EXPECT_EQ(ab[0], std::make_pair(std::size_t{0}, std::size_t{0}));
  EXPECT_EQ(ab[1], std::make_pair(std::size_t{1}, std::size_t{1}));
  ASSERT_EQ(bc.size(), 1u);
  EXPECT_EQ(bc[0], std::make_pair(std::size_t{1}, std::size_t{0}));
}

TEST(LaneletPairing, ADoubleLineIsOneBoundary) {
  // A double line (y 0 and 0.3) and a line 3.5 m beyond it: one lane, from the double's left
  // line (the nearest to the lane) to the far line; none from the double's right line.
  const LaneletLayout layout =
      PairLanelets({Straight(0.0, 0, 60), Straight(0.3, 0, 60), Straight(3.8, 0, 60)});
  ASSERT_EQ(layout.lanelets.size(), 1u);
  EXPECT_EQ(layout.lanelets[0].right_line, 1u);
  EXPECT_EQ(layout.lanelets[0].left_line, 2u);
}

TEST(LaneletPairing, NoLaneBetweenLinesTooFarApartOrTooShortOrOpposed) {
  EXPECT_TRUE(PairLanelets({Straight(0.0, 0, 100), Straight(8.0, 0, 100)}).lanelets.empty());
  EXPECT_TRUE(PairLanelets({Straight(0.0, 0, 100), Straight(3.5, 40, 46)}).lanelets.empty());
  std::vector<Eigen::Vector3d> reversed = Straight(3.5, 0, 100);
  std::reverse(reversed.begin(), reversed.end());
  EXPECT_TRUE(PairLanelets({Straight(0.0, 0, 100), reversed}).lanelets.empty());
}

TEST(LaneletPairing, ALaneThroughACurveStaysOneLanelet) {
  // R 30 m, 90 deg, lines 3.5 m apart.
  const LaneletLayout layout = PairLanelets({Arc(30.0, 0.0, M_PI / 2), Arc(30.0, 3.5, M_PI / 2)});
  ASSERT_EQ(layout.lanelets.size(), 1u);
  EXPECT_EQ(layout.lanelets[0].right_line, 0u);
}

TEST(LaneletPairing, LinesAreOrientedAlongTheDrive) {
  std::vector<StampedPose> drive(3);
  for (int k = 0; k < 3; ++k) drive[k].T_map_base.translation() = Eigen::Vector3d(40.0 * k, 0, 0);
  const std::vector<Eigen::Vector3d> along = Straight(1.75, 0, 100);
  std::vector<Eigen::Vector3d> against = along;
  std::reverse(against.begin(), against.end());
  EXPECT_EQ(LaneOrientedAlongDrive(against, drive).front(), along.front());
  EXPECT_EQ(LaneOrientedAlongDrive(along, drive).front(), along.front());
  // Driving the other way (heading -x): the line is turned.
  for (StampedPose& p : drive)
    p.T_map_base.linear() = Eigen::Matrix3d(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()));
  EXPECT_EQ(LaneOrientedAlongDrive(along, drive).front(), along.back());
  EXPECT_EQ(LaneOrientedAlongDrive(along, {}).front(), along.front());  // no trajectory
}

TEST(LaneletPairing, AbsurdLinesAreNoLanesAndCostNothing) {
  // A two-point "line" 1e9 m long beside a real one, a line at 1e300 m and a point line: no
  // lanelet, no hang, no overflow.
  const std::vector<Eigen::Vector3d> huge = {{0, 3.5, 0}, {1e9, 3.5, 0}};
  const std::vector<Eigen::Vector3d> far = {{1e300, 0, 0}, {1e300, 10, 0}};
  const std::vector<Eigen::Vector3d> point = {{5, 5, 0}, {5, 5, 0}};
  const LaneletLayout layout = PairLanelets({Straight(0.0, 0, 100), huge, far, point});
  EXPECT_TRUE(layout.lanelets.empty());
  EXPECT_EQ(GridCell(1e300, 5.0), GridCell(2e12, 5.0));
  EXPECT_EQ(GridCell(std::nan(""), 5.0), 0);
  EXPECT_EQ(GridCell(-7.0, 5.0), -2);
}

TEST(LaneletPairing, ArcLengthsAndPoints) {
  const std::vector<Eigen::Vector3d> line = {{0, 0, 0}, {3, 4, 1}, {3, 10, 1}};
  const std::vector<double> arc = ArcLengths(line);
  ASSERT_EQ(arc.size(), 3u);
  EXPECT_DOUBLE_EQ(arc[1], 5.0);
  EXPECT_DOUBLE_EQ(arc[2], 11.0);
  EXPECT_TRUE(PointAtArcLength(line, arc, 2.5).isApprox(Eigen::Vector3d(1.5, 2.0, 0.5)));
  EXPECT_TRUE(PointAtArcLength(line, arc, -1.0).isApprox(line.front()));
  EXPECT_TRUE(PointAtArcLength(line, arc, 20.0).isApprox(line.back()));
}

}  // namespace
}  // namespace ipm_road_mapper
