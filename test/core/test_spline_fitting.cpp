#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <stdexcept>
#include <utility>
#include <vector>

#include "ipm_road_mapper/core/geometry/catmull_rom_spline.h"
#include "ipm_road_mapper/core/geometry/spline_fitting.h"

namespace ipm_road_mapper {
namespace {

// A circular lane in the z = 0 plane, far from the origin like map coordinates: arc length
// a >= 0 from its start, counter-clockwise.
struct ArcLane {
  Eigen::Vector2d center{4.0e3, -2.5e3};
  double radius = 100.0;
  double start_angle = -0.3;

  Eigen::Vector3d At(double a) const {
    const double angle = start_angle + a / radius;
    return Eigen::Vector3d(center.x() + radius * std::cos(angle),
                           center.y() + radius * std::sin(angle), 0.0);
  }
  // Distance from p to the (infinite) circle.
  double Distance(const Eigen::Vector3d& p) const {
    return std::hypot((p.head<2>() - center).norm() - radius, p.z());
  }
  // Arc position of p's projection on the circle (valid within half a turn of the start).
  double ArcPosition(const Eigen::Vector3d& p) const {
    const Eigen::Vector2d d = p.head<2>() - center;
    return radius * std::remainder(std::atan2(d.y(), d.x()) - start_angle, 2 * M_PI);
  }
};

// Noisy points at arc positions `positions` (isotropic Gaussian noise, fixed seed).
std::vector<Eigen::Vector3d> NoisyPoints(const ArcLane& lane, const std::vector<double>& positions,
                                         double sigma, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, sigma);
  std::vector<Eigen::Vector3d> points;
  for (double a : positions) {
    points.push_back(lane.At(a) + Eigen::Vector3d(noise(rng), noise(rng), noise(rng)));
  }
  return points;
}

std::vector<double> EvenPositions(double from, double to, double step) {
  std::vector<double> positions;
  for (int k = 0; from + k * step <= to + 1e-9; ++k) positions.push_back(from + k * step);
  return positions;
}

// Largest distance of the spline's 0.1 m samples to the true lane.
double MaxDeviation(const ArcLane& lane, const CatmullRomSpline& spline) {
  double worst = 0.0;
  for (const Eigen::Vector3d& p : spline.SampleByArcLength(0.1)) {
    worst = std::max(worst, lane.Distance(p));
  }
  return worst;
}

// Arc positions (on the true lane) of the spline's start and end, in increasing order.
std::pair<double, double> Coverage(const ArcLane& lane, const CatmullRomSpline& spline) {
  const double a = lane.ArcPosition(spline.Evaluate(0.0));
  const double b = lane.ArcPosition(spline.Evaluate(spline.NumSegments()));
  return {std::min(a, b), std::max(a, b)};
}

CatmullRomSpline Fit(const std::vector<Eigen::Vector3d>& points) {
  const auto control_points = EstimateControlPoints(points, SplineFitOptions());
  if (!control_points) throw std::runtime_error("no fit");
  return CatmullRomSpline(*control_points);
}

TEST(SplineFitting, StraightLineWithNoise) {
  const Eigen::Vector3d origin(-1200.0, 350.0, 12.0);
  const Eigen::Vector3d direction =
      Eigen::Vector3d(std::cos(0.5), std::sin(0.5), 0.01).normalized();
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> along(0.0, 40.0);
  std::normal_distribution<double> noise(0.0, 0.1);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 400; ++i) {
    points.push_back(origin + along(rng) * direction +
                     Eigen::Vector3d(noise(rng), noise(rng), noise(rng)));
  }
  const CatmullRomSpline spline = Fit(points);
  double worst = 0.0;
  for (const Eigen::Vector3d& p : spline.SampleByArcLength(0.1)) {
    const Eigen::Vector3d d = p - origin;
    worst = std::max(worst, (d - d.dot(direction) * direction).norm());
  }
  std::printf("straight line, noise 0.1 m: max deviation %.4f m, length %.2f m\n", worst,
              spline.Length());
  EXPECT_LT(worst, 0.05);
  EXPECT_GT(spline.Length(), 0.95 * 40.0);
  // Direction convention: increasing projection on the principal axis with positive x.
  EXPECT_GT(spline.Evaluate(spline.NumSegments()).x(), spline.Evaluate(0.0).x());
}

TEST(SplineFitting, NoisyShuffledArcIsFollowedAndCovered) {
  const ArcLane lane;  // R = 100 m
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> along(0.0, 60.0);
  std::vector<double> positions(600);
  for (double& a : positions) a = along(rng);
  std::vector<Eigen::Vector3d> points = NoisyPoints(lane, positions, 0.05, 3);
  std::shuffle(points.begin(), points.end(), rng);
  const CatmullRomSpline spline = Fit(points);
  const double worst = MaxDeviation(lane, spline);
  const auto [begin, end] = Coverage(lane, spline);
  std::printf("arc R=100 60 m, noise 0.05 m: max deviation %.4f m, covers [%.3f, %.3f] m\n", worst,
              begin, end);
  EXPECT_LT(worst, 0.05);
  EXPECT_GE(end - begin, 0.95 * 60.0);
}

TEST(SplineFitting, LongDashedCurveIsFollowed) {
  ArcLane lane;
  lane.radius = 150.0;  // 300 m of it turn by 2 rad: no global polynomial in x or y fits
  std::vector<double> positions;
  for (double dash = 0.0; dash <= 297.0; dash += 9.0) {  // 3 m dash, 6 m gap
    for (double a : EvenPositions(dash, dash + 3.0, 0.1)) positions.push_back(a);
  }
  std::vector<Eigen::Vector3d> points = NoisyPoints(lane, positions, 0.05, 4);
  std::mt19937 rng(5);
  std::shuffle(points.begin(), points.end(), rng);
  const CatmullRomSpline spline = Fit(points);
  const double worst = MaxDeviation(lane, spline);
  const auto [begin, end] = Coverage(lane, spline);
  std::printf("dashed arc R=150 300 m: max deviation %.4f m, covers [%.3f, %.3f] m\n", worst, begin,
              end);
  EXPECT_LT(worst, 0.05);
  EXPECT_GE(end - begin, 0.95 * 300.0);
}

TEST(SplineFitting, OutliersDoNotPullTheCurve) {
  const ArcLane lane;
  std::mt19937 rng(6);
  std::uniform_real_distribution<double> along(0.0, 60.0), offset(1.0, 2.0);
  std::vector<double> positions(540);
  for (double& a : positions) a = along(rng);
  std::vector<Eigen::Vector3d> points = NoisyPoints(lane, positions, 0.05, 7);
  // 10% outliers, all on the outer side (the worst case: they do not cancel out).
  for (int i = 0; i < 60; ++i) {
    const double a = along(rng);
    const Eigen::Vector3d outward =
        (Eigen::Vector3d() << (lane.At(a).head<2>() - lane.center).normalized(), 0.0).finished();
    points.push_back(lane.At(a) + offset(rng) * outward);
  }
  std::shuffle(points.begin(), points.end(), rng);
  const CatmullRomSpline spline = Fit(points);
  const double worst = MaxDeviation(lane, spline);
  std::printf("arc with 10%% outliers 1-2 m: max deviation %.4f m\n", worst);
  EXPECT_LT(worst, 0.1);
}

// Intervals of the on-curve control points c_1..c_{n-2}: every one but the last is a full chord
// spacing, the last is in [spacing / 2, 3 spacing / 2].
void ExpectChordSpacing(const std::vector<Eigen::Vector3d>& c, double spacing) {
  const size_t n = c.size();
  for (size_t k = 2; k + 1 < n; ++k) {
    const double interval = (c[k] - c[k - 1]).norm();
    if (k + 2 < n) {
      EXPECT_NEAR(interval, spacing, 1e-3) << k;  // chord of a 3 m arc at R = 100: -0.1 mm
    } else {
      EXPECT_GE(interval, 0.5 * spacing - 1e-3) << k;
      EXPECT_LE(interval, 1.5 * spacing + 1e-3) << k;
    }
  }
}

TEST(SplineFitting, ControlPointsAreAtChordSpacingWithLinearPhantoms) {
  const ArcLane lane;
  const std::vector<Eigen::Vector3d> points =
      NoisyPoints(lane, EvenPositions(0.0, 50.0, 0.1), 0.05, 8);
  const auto c = EstimateControlPoints(points, SplineFitOptions());
  ASSERT_TRUE(c.has_value());
  const size_t n = c->size();
  ASSERT_GE(n, 19u);  // 50 m / 3 m -> 17 intervals, 18 on-curve points, 2 phantoms
  ExpectChordSpacing(*c, 3.0);
  EXPECT_LT(((*c)[0] - (2.0 * (*c)[1] - (*c)[2])).norm(), 1e-9);
  EXPECT_LT(((*c)[n - 1] - (2.0 * (*c)[n - 2] - (*c)[n - 3])).norm(), 1e-9);
}

TEST(SplineFitting, TooFewOrTooShortGivesNoFit) {
  const ArcLane lane;
  const SplineFitOptions options;
  EXPECT_FALSE(EstimateControlPoints(NoisyPoints(lane, {0.0, 5.0, 10.0, 15.0}, 0.0, 9), options));
  EXPECT_FALSE(EstimateControlPoints({}, options));
  // Enough points, but all within 0.5 m along the lane.
  EXPECT_FALSE(
      EstimateControlPoints(NoisyPoints(lane, EvenPositions(0.0, 0.5, 0.05), 0.0, 9), options));
  EXPECT_TRUE(
      EstimateControlPoints(NoisyPoints(lane, EvenPositions(0.0, 5.0, 1.0), 0.0, 9), options));
}

TEST(SplineFitting, SameInputGivesSameOutput) {
  const ArcLane lane;
  const std::vector<Eigen::Vector3d> points =
      NoisyPoints(lane, EvenPositions(0.0, 30.0, 0.2), 0.1, 10);
  const auto first = EstimateControlPoints(points, SplineFitOptions());
  const auto second = EstimateControlPoints(points, SplineFitOptions());
  ASSERT_TRUE(first && second);
  ASSERT_EQ(first->size(), second->size());
  for (size_t k = 0; k < first->size(); ++k) EXPECT_EQ((*first)[k], (*second)[k]);
}

}  // namespace
}  // namespace ipm_road_mapper
