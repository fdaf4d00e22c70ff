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
