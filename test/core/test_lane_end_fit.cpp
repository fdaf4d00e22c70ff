// FitLaneEnds: growth by whole chord spacings, convergence of a wrong tail to the data,
// growth at the start, and everything the points do not reach left bit for bit.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "ipm_road_mapper/core/geometry/catmull_rom_spline.h"
#include "ipm_road_mapper/core/geometry/lane_end_fit.h"

namespace ipm_road_mapper {
namespace {

// Control points every 3 m along y = offset from x0 to x1, phantom ends included.
std::vector<Eigen::Vector3d> StraightControlPoints(double x0, double x1, double offset = 0.0) {
  std::vector<Eigen::Vector3d> cps;
  for (double x = x0 - 3.0; x <= x1 + 3.0 + 1e-9; x += 3.0) cps.emplace_back(x, offset, 0.0);
  return cps;
}

// Points every `step` m along y = offset over [x0, x1], with Gaussian noise.
std::vector<Eigen::Vector3d> LinePoints(double x0, double x1, double offset, double step,
                                        double noise, std::mt19937* rng) {
  std::normal_distribution<double> n(0.0, noise);
  std::vector<Eigen::Vector3d> points;
  for (double x = x0; x <= x1 + 1e-9; x += step) points.emplace_back(x, offset + n(*rng), n(*rng));
  return points;
}

// Distance from p to the circle of radius R centered at (0, R) (a left turn from the origin).
double DistanceToArc(const Eigen::Vector3d& p, double R) {
  return std::abs(std::hypot(p.x(), p.y() - R) - R);
}

TEST(FitLaneEnds, ExtendsByWholeChordSpacingsAlongTheLine) {
  const auto cps = StraightControlPoints(0.0, 12.0);  // real points at 0, 3, ..., 12
  std::mt19937 rng(1);
  const auto points = LinePoints(10.0, 19.4, 0.0, 0.2, 0.0, &rng);  // 7.4 m past the end
  int added_at_start = -1;
  const auto grown = FitLaneEnds(cps, points, LaneEndFitOptions(), &added_at_start);
  EXPECT_EQ(added_at_start, 0);
  // 7.4 m / 3 m rounds to 2 new points: the last real one at x = 18.
  ASSERT_EQ(grown.size(), cps.size() + 2);
  EXPECT_NEAR(grown[grown.size() - 2].x(), 18.0, 1e-6);
  for (std::size_t i = 1; i + 1 < grown.size(); ++i) {
    EXPECT_NEAR(grown[i].y(), 0.0, 1e-9);
    EXPECT_NEAR(grown[i].x(), 3.0 * (static_cast<double>(i) - 1.0), 1e-6);
  }
  // The phantom end continues the line.
  EXPECT_NEAR((grown.back() - 2.0 * grown[grown.size() - 2] + grown[grown.size() - 3]).norm(), 0.0,
              1e-9);
}

// Control points every 3 m of arc along a circle of radius R through the origin (center at
// (0, side R): side +1 a left turn), from arc length s0 to s1, phantom ends included.
std::vector<Eigen::Vector3d> ArcControlPoints(double R, double side, double s0, double s1) {
  std::vector<Eigen::Vector3d> cps;
  for (double s = s0 - 3.0; s <= s1 + 3.0 + 1e-9; s += 3.0) {
    cps.emplace_back(R * std::sin(s / R), side * R * (1.0 - std::cos(s / R)), 0.0);
  }
  return cps;
}

// An end on an R 30 m arc (curvy's tightest) with growth points on the arc beyond it. Grown
// straight along the last chord (main's growth), the new control points leave the line by
// about d^2 / 2R (1.7 m in 10 m) and the points past 8 m are no longer within
// max_point_distance_m of the tangent line; grown along the arc of the line's curvature,
// they stay on it, for left and right turns and at the start.
TEST(FitLaneEnds, GrowsAlongTheArcOfTheGivenCurvature) {
  const double R = 30.0;
  for (const double side : {1.0, -1.0}) {
    const auto cps = ArcControlPoints(R, side, 0.0, 12.0);
    std::vector<Eigen::Vector3d> beyond;
    for (double s = 12.5; s <= 24.0 + 1e-9; s += 0.25) {
      beyond.emplace_back(R * std::sin(s / R), side * R * (1.0 - std::cos(s / R)), 0.0);
    }
    const auto on_arc = [&](const Eigen::Vector3d& p) {
      return std::abs(std::hypot(p.x(), p.y() - side * R) - R);
    };
    LaneEndFitOptions options;
    // Growth alone: no refinement samples, so the new points are where the growth put them.
    const auto straight = FitLaneEnds(cps, {}, options, nullptr, &beyond);
    const auto curved =
        FitLaneEnds(cps, {}, options, nullptr, &beyond, LaneEndCurvatures{0.0, side / R});
    ASSERT_EQ(curved.size(), cps.size() + 4);  // 12 m of arc: 4 chords
    double straight_error = 0.0, curved_error = 0.0;
    for (std::size_t i = cps.size() - 1; i + 1 < straight.size(); ++i) {
      straight_error = std::max(straight_error, on_arc(straight[i]));
    }
    for (std::size_t i = cps.size() - 1; i + 1 < curved.size(); ++i) {
      curved_error = std::max(curved_error, on_arc(curved[i]));
    }
    // What is left on the arc is the refinement's second differences (0.3 m per chord on
    // R 30 m), which pull toward a straight line against the weak growth points.
    EXPECT_GT(straight_error, 0.5) << "side " << side;
    EXPECT_LT(curved_error, 0.15) << "side " << side;
    // The start, grown backwards along the same circle (the lane's start-to-end curvature).
    std::vector<Eigen::Vector3d> before;
    for (double s = -0.5; s >= -9.0 - 1e-9; s -= 0.25) {
      before.emplace_back(R * std::sin(s / R), side * R * (1.0 - std::cos(s / R)), 0.0);
    }
    int added_at_start = 0;
    const auto at_start =
        FitLaneEnds(cps, {}, options, &added_at_start, &before, LaneEndCurvatures{side / R, 0.0});
    ASSERT_EQ(added_at_start, 3);
    for (int i = 1; i <= 3; ++i) EXPECT_LT(on_arc(at_start[i]), 0.15) << "side " << side;
  }
}

// Leaving a curve: the path's curvature still has the arc's while the end is already past
// it. When the points beyond the end lie along the straight line, not the arc, the end grows
// straight (as with no curvature).
TEST(FitLaneEnds, AnEndPastTheCurveGrowsStraightWhenItsPointsDo) {
  const double R = 30.0;
  const auto cps = ArcControlPoints(R, 1.0, 0.0, 12.0);
  const double a = 12.0 / R;
  const Eigen::Vector3d end(R * std::sin(a), R * (1.0 - std::cos(a)), 0.0);
  const Eigen::Vector3d tangent(std::cos(a), std::sin(a), 0.0);
  std::vector<Eigen::Vector3d> beyond;
  for (double s = 0.5; s <= 12.0 + 1e-9; s += 0.25) beyond.push_back(end + s * tangent);
  const LaneEndFitOptions options;
  const auto straight = FitLaneEnds(cps, {}, options, nullptr, &beyond);
  const auto curved =
      FitLaneEnds(cps, {}, options, nullptr, &beyond, LaneEndCurvatures{0.0, 1.0 / R});
  ASSERT_GT(straight.size(), cps.size());
  EXPECT_EQ(curved, straight);
}

// Curved growth still ignores a neighbour's points: the line 3.5 m inside on the same arc.
TEST(FitLaneEnds, CurvedGrowthIgnoresTheConcentricNeighbour) {
  const double R = 30.0;
  const auto cps = ArcControlPoints(R, 1.0, 0.0, 12.0);
  std::vector<Eigen::Vector3d> neighbour;
  const double r = R - 3.5;
  for (double s = 12.5; s <= 24.0 + 1e-9; s += 0.25) {
    neighbour.emplace_back(r * std::sin(s / R), R - r * std::cos(s / R), 0.0);
  }
  EXPECT_EQ(FitLaneEnds(cps, {}, LaneEndFitOptions(), nullptr, &neighbour,
                        LaneEndCurvatures{0.0, 1.0 / R}),
            cps);
}

TEST(FitLaneEnds, FewOrDistantPointsDoNotExtend) {
  const auto cps = StraightControlPoints(0.0, 12.0);
  // Four points past the end (one fewer than min_points_to_extend)...
  std::vector<Eigen::Vector3d> few = {{14, 0, 0}, {15, 0, 0}, {16, 0, 0}, {17, 0, 0}};
  EXPECT_EQ(FitLaneEnds(cps, few, LaneEndFitOptions()).size(), cps.size());
  // ... and many, but 3 m beside the lane's line (another lane line).
  std::mt19937 rng(2);
  const auto beside = LinePoints(13.0, 25.0, 3.0, 0.5, 0.0, &rng);
  EXPECT_EQ(FitLaneEnds(cps, beside, LaneEndFitOptions()), cps);
}

TEST(FitLaneEnds, WrongTailConvergesToTheDataAndTheRestIsUntouched) {
  // A lane along an arc of R = 150 m whose last three control points bend 0.6 m outwards
  // (a noisy far observation started it); noisy samples of the true arc arrive frame by frame.
  const double R = 150.0;
  std::vector<Eigen::Vector3d> cps;
  for (int k = -1; k <= 10; ++k) {
    const double a = 3.0 * k / R;
    cps.emplace_back(R * std::sin(a), R * (1.0 - std::cos(a)), 0.0);
  }
  const std::vector<Eigen::Vector3d> truth = cps;
  for (int j = 0; j < 3; ++j) cps[cps.size() - 2 - j].y() -= 0.6 * (3 - j) / 3.0;
  cps.back() = 2.0 * cps[cps.size() - 2] - cps[cps.size() - 3];
  const std::vector<Eigen::Vector3d> before = cps;
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.05);
  // As the mapper does: each call sees the points of the last 10 frames.
  std::vector<std::vector<Eigen::Vector3d>> frames;
  for (int frame = 0; frame < 20; ++frame) {
    frames.emplace_back();
    for (double s = 20.0; s <= 27.0; s += 0.25) {  // the last 7 m of the lane
      const double a = s / R;
      frames.back().emplace_back(R * std::sin(a) + noise(rng), R * (1.0 - std::cos(a)) + noise(rng),
                                 noise(rng));
    }
    std::vector<Eigen::Vector3d> points;
    for (std::size_t f = frames.size() > 10 ? frames.size() - 10 : 0; f < frames.size(); ++f) {
      points.insert(points.end(), frames[f].begin(), frames[f].end());
    }
    cps = FitLaneEnds(cps, points, LaneEndFitOptions());
    ASSERT_EQ(cps.size(), before.size());
  }
  // The samples cover segments 6.. of 9; control points 0..5 are not reached.
  for (std::size_t i = 0; i <= 5; ++i) EXPECT_EQ(cps[i], before[i]) << i;
  const CatmullRomSpline fitted(cps);
  for (double s = 7.0; s <= fitted.NumSegments(); s += 0.1) {
    EXPECT_LT(DistanceToArc(fitted.Evaluate(s), R), 0.015) << "s = " << s;
  }
  for (std::size_t i = 7; i + 1 < cps.size(); ++i) {
    EXPECT_LT((cps[i] - truth[i]).norm(), 0.1) << i;  // evenly spaced again, on the arc
  }
}

TEST(FitLaneEnds, GrowsAtTheStartAndReportsTheShift) {
  const auto cps = StraightControlPoints(10.0, 22.0, 1.5);
  std::mt19937 rng(4);
  const auto points = LinePoints(2.0, 11.0, 1.5, 0.25, 0.02, &rng);  // 8 m before the start
  int added_at_start = 0;
  const auto grown = FitLaneEnds(cps, points, LaneEndFitOptions(), &added_at_start);
  EXPECT_EQ(added_at_start, 3);  // round(8 / 3): the first real point at x = 1
  ASSERT_EQ(grown.size(), cps.size() + 3);
  EXPECT_NEAR(grown[1].x(), 1.0, 0.15);
  EXPECT_NEAR(grown[1].y(), 1.5, 0.05);
  // The far end is beyond the points' reach: kept bit for bit, shifted by 3.
  for (std::size_t i = cps.size() - 3; i < cps.size(); ++i) EXPECT_EQ(grown[i + 3], cps[i]);
}

TEST(FitLaneEnds, IgnoresNonFinitePointsAndRejectsShortLanes) {
  const auto cps = StraightControlPoints(0.0, 12.0);
  std::vector<Eigen::Vector3d> points = {{std::nan(""), 0, 0}, {5, 0.1, 0}};
  const auto out = FitLaneEnds(cps, points, LaneEndFitOptions());
  for (const auto& c : out) EXPECT_TRUE(c.allFinite());
  EXPECT_THROW(FitLaneEnds({{0, 0, 0}, {1, 0, 0}, {2, 0, 0}}, points, LaneEndFitOptions()),
               std::invalid_argument);
}

}  // namespace
}  // namespace ipm_road_mapper

// FitLaneEndsNear: the whole-lane result from the part near the points, on a lane 3 km long
// (growth at the end past a gap, growth at the start, a refit of the middle).
namespace ipm_road_mapper {
namespace {

std::vector<Eigen::Vector3d> WavyControlPoints(double x0, double x1) {
  std::vector<Eigen::Vector3d> cps;
  for (double x = x0 - 3.0; x <= x1 + 3.0 + 1e-9; x += 3.0) {
    cps.emplace_back(x, 0.5 * std::sin(x / 50.0), 0.0);
  }
  return cps;
}

void ExpectSameFit(const std::vector<Eigen::Vector3d>& cps,
                   const std::vector<Eigen::Vector3d>& points,
                   const std::vector<Eigen::Vector3d>& growth) {
  int added_whole = -1, added_near = -1;
  const auto whole = FitLaneEnds(cps, points, LaneEndFitOptions(), &added_whole, &growth);
  std::vector<Eigen::Vector3d> near = cps;
  FitLaneEndsNear(LaneEndFitOptions(), points, growth, &near, &added_near);
  EXPECT_EQ(added_near, added_whole);
  ASSERT_EQ(near.size(), whole.size());
  for (std::size_t j = 0; j < whole.size(); ++j) {
    EXPECT_LT((near[j] - whole[j]).norm(), 1e-9) << "control point " << j;
  }
}

TEST(FitLaneEndsNear, EqualsTheWholeLaneFitAtTheEndPastAGap) {
  const auto cps = WavyControlPoints(0.0, 3000.0);
  std::mt19937 rng(3);
  // The recent observations near the end, 0.3 m off (a tail to pull), and growth points
  // starting 12 m past the end (a dash gap) reaching 20 m beyond it.
  const auto points = LinePoints(2985.0, 2999.0, 0.3, 0.5, 0.02, &rng);
  const auto growth = LinePoints(3012.0, 3020.0, 0.3, 0.5, 0.02, &rng);
  ExpectSameFit(cps, points, points);
  ExpectSameFit(cps, points, growth);
  std::vector<Eigen::Vector3d> near = cps;
  int added = 0;
  FitLaneEndsNear(LaneEndFitOptions(), points, growth, &near, &added);
  EXPECT_GT(near.size(), cps.size());                                            // it grew
  for (std::size_t j = 0; j + 20 < cps.size(); ++j) EXPECT_EQ(near[j], cps[j]);  // untouched
}

TEST(FitLaneEndsNear, EqualsTheWholeLaneFitAtTheStartAndInTheMiddle) {
  const auto cps = WavyControlPoints(0.0, 3000.0);
  std::mt19937 rng(4);
  const auto start = LinePoints(-9.0, 6.0, 0.2, 0.5, 0.02, &rng);  // 9 m before the start
  ExpectSameFit(cps, start, start);
  const auto middle = LinePoints(1500.0, 1515.0, 0.2, 0.5, 0.02, &rng);
  ExpectSameFit(cps, middle, middle);
  ExpectSameFit(cps, {}, {});  // nothing near: unchanged
}

}  // namespace
}  // namespace ipm_road_mapper
