#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

#include "ipm_road_mapper/core/geometry/catmull_rom_spline.h"

namespace ipm_road_mapper {
namespace {

// An irregular, non-planar set of control points.
std::vector<Eigen::Vector3d> WigglyControlPoints() {
  return {{0.0, 0.0, 0.0},  {3.0, 0.5, 0.1},    {6.0, 2.0, 0.3},   {8.5, 4.5, 0.2},
          {10.0, 8.0, 0.0}, {10.5, 11.0, -0.2}, {12.0, 14.0, -0.1}};
}

// Control points on a circle of radius R (center at the origin), `step` radians apart.
std::vector<Eigen::Vector3d> CircleControlPoints(double radius, double step, int count) {
  std::vector<Eigen::Vector3d> points;
  for (int k = 0; k < count; ++k) {
    points.emplace_back(radius * std::cos(k * step), radius * std::sin(k * step), 0.0);
  }
  return points;
}

TEST(CatmullRomSpline, PassesThroughInteriorControlPointsAtIntegerParameters) {
  const std::vector<Eigen::Vector3d> c = WigglyControlPoints();
  const CatmullRomSpline spline(c);
  ASSERT_EQ(spline.NumSegments(), static_cast<int>(c.size()) - 3);
  for (int k = 0; k <= spline.NumSegments(); ++k) {
    EXPECT_LT((spline.Evaluate(k) - c[k + 1]).norm(), 1e-12) << "s = " << k;
  }
  // Parameters outside [0, n-3] clamp to the ends.
  EXPECT_LT((spline.Evaluate(-2.0) - c[1]).norm(), 1e-12);
  EXPECT_LT((spline.Evaluate(100.0) - c[c.size() - 2]).norm(), 1e-12);
}

TEST(CatmullRomSpline, DerivativeMatchesCentralDifferences) {
  const CatmullRomSpline spline(WigglyControlPoints());
  const double h = 1e-6;
  for (double s : {0.1, 0.5, 0.999, 1.25, 2.0 + 1e-3, 2.7, 3.5, 3.9}) {
    const Eigen::Vector3d numeric = (spline.Evaluate(s + h) - spline.Evaluate(s - h)) / (2 * h);
    EXPECT_LT((spline.Derivative(s) - numeric).norm(), 1e-6) << "s = " << s;
  }
  // C1 across a segment boundary: at c_2, p'(1) of segment 0 (points c_0..c_3) is
  // (c_3 - c_1) / 2, and so is p'(0) of segment 1 (points c_1..c_4).
  const std::vector<Eigen::Vector3d> c = WigglyControlPoints();
  EXPECT_LT((spline.Derivative(1.0 - 1e-12) - 0.5 * (c[3] - c[1])).norm(), 1e-9);
  EXPECT_LT((spline.Derivative(1.0) - 0.5 * (c[3] - c[1])).norm(), 1e-12);
}

TEST(CatmullRomSpline, CollinearEquallySpacedControlPointsGiveLinearParametrization) {
  // c_k = c_0 + k d: the u^2 and u^3 coefficients vanish, p(s) = c_1 + s d.
  const Eigen::Vector3d c0(1.0, -2.0, 0.5), d(2.0, 1.0, -0.25);
  std::vector<Eigen::Vector3d> c;
  for (int k = 0; k < 6; ++k) c.push_back(c0 + k * d);
  const CatmullRomSpline spline(c);
  for (double s : {0.0, 0.3, 0.5, 1.7, 2.25, 3.0}) {
    EXPECT_LT((spline.Evaluate(s) - (c[1] + s * d)).norm(), 1e-12) << "s = " << s;
    EXPECT_LT((spline.Derivative(s) - d).norm(), 1e-12) << "s = " << s;
  }
}

TEST(CatmullRomSpline, BasisMatchesHandComputedValues) {
  // At u = 1/2 the basis gives p = (-c0 + 9 c1 + 9 c2 - c3) / 16:
  //   c0: 0.5 (-1/2 + 2/4 - 1/8) = -1/16,   c1: 0.5 (2 - 5/4 + 3/8) = 9/16,
  //   c2: 0.5 (1/2 + 4/4 - 3/8)  =  9/16,   c3: 0.5 (-1/4 + 1/8)    = -1/16.
  // With the points below: x = (0 + 9 + 18 - 3) / 16 = 1.5, y = (9 - 3) / 16 = 0.375,
  // z = -16 / 16 = -1.
  const std::vector<Eigen::Vector3d> c = {
      {0.0, 0.0, 0.0}, {1.0, 0.0, 0.0}, {2.0, 1.0, 0.0}, {3.0, 3.0, 16.0}};
  const CatmullRomSpline spline(c);
  EXPECT_LT((spline.Evaluate(0.5) - Eigen::Vector3d(1.5, 0.375, -1.0)).norm(), 1e-12);
  // At u = 1/4: c0 0.5 (-1/4 + 2/16 - 1/64) = -9/128, c1 0.5 (2 - 5/16 + 3/64) = 111/128,
  // c2 0.5 (1/4 + 4/16 - 3/64) = 29/128, c3 0.5 (-1/16 + 1/64) = -3/128:
  // x = (111 + 58 - 9) / 128 = 1.25, y = (29 - 9) / 128 = 0.15625, z = -48 / 128 = -0.375.
  EXPECT_LT((spline.Evaluate(0.25) - Eigen::Vector3d(1.25, 0.15625, -0.375)).norm(), 1e-12);
  // End tangents (c2 - c0) / 2 and (c3 - c1) / 2.
  EXPECT_LT((spline.Derivative(0.0) - Eigen::Vector3d(1.0, 0.5, 0.0)).norm(), 1e-12);
  EXPECT_LT((spline.Derivative(1.0) - Eigen::Vector3d(1.0, 1.5, 8.0)).norm(), 1e-12);
}

TEST(CatmullRomSpline, EvaluateSegmentAgreesWithEvaluate) {
  const std::vector<Eigen::Vector3d> c = WigglyControlPoints();
  const CatmullRomSpline spline(c);
  for (int i = 0; i < spline.NumSegments(); ++i) {
    for (double u : {0.0, 0.2, 0.5, 0.8, 1.0}) {
      const Eigen::Vector3d p =
          CatmullRomSpline::EvaluateSegment<double>(c[i], c[i + 1], c[i + 2], c[i + 3], u);
      EXPECT_LT((p - spline.Evaluate(i + u)).norm(), 1e-12) << i << " " << u;
    }
  }
}

TEST(CatmullRomSpline, LengthOfStraightAndCircularSplines) {
  const Eigen::Vector3d direction = Eigen::Vector3d(1.0, 2.0, 2.0) / 3.0;  // unit
  std::vector<Eigen::Vector3d> line;
  for (int k = 0; k < 8; ++k) line.push_back(Eigen::Vector3d(5, -3, 1) + 1.5 * k * direction);
  const CatmullRomSpline straight(line);
  EXPECT_NEAR(straight.Length(), 5 * 1.5, 1e-9);
  EXPECT_NEAR(straight.ArcLengthAt(2.5), 2.5 * 1.5, 1e-9);
  EXPECT_NEAR(straight.ParameterAtArcLength(4.0), 4.0 / 1.5, 1e-9);

  // Control points 3 degrees apart on R = 50 m: the curve hugs the circle, so its length is
  // R times the angle between c_1 and c_{n-2} (to well below a millimeter).
  const double step = 3.0 * M_PI / 180.0;
  const CatmullRomSpline arc(CircleControlPoints(50.0, step, 12));
  EXPECT_NEAR(arc.Length(), 50.0 * 9 * step, 1e-3);
  for (double a : {0.0, 1.0, 7.3, 15.0, arc.Length()}) {
    EXPECT_NEAR(arc.ArcLengthAt(arc.ParameterAtArcLength(a)), a, 1e-8) << a;
  }
}

TEST(CatmullRomSpline, SampleByArcLengthIsEquallySpacedAndEndsAtTheEnd) {
  const CatmullRomSpline spline(CircleControlPoints(20.0, 0.1, 10));  // L ~ 14 m
  const double spacing = 0.5;
  const std::vector<Eigen::Vector3d> samples = spline.SampleByArcLength(spacing);
  ASSERT_EQ(samples.size(), static_cast<size_t>(std::ceil(spline.Length() / spacing)) + 1);
  EXPECT_LT((samples.front() - spline.Evaluate(0.0)).norm(), 1e-12);
  EXPECT_LT((samples.back() - spline.Evaluate(spline.NumSegments())).norm(), 1e-12);
  // Chord of a 0.5 m arc on R ~ 20 m is shorter than the arc by a^3 / (24 R^2) ~ 1e-5 m.
  for (size_t k = 1; k + 1 < samples.size(); ++k) {
    EXPECT_NEAR((samples[k] - samples[k - 1]).norm(), spacing, 1e-4) << k;
  }
  const double last_gap = (samples.back() - samples[samples.size() - 2]).norm();
  EXPECT_GT(last_gap, 0.0);
  EXPECT_LE(last_gap, spacing + 1e-9);
  EXPECT_THROW(spline.SampleByArcLength(0.0), std::invalid_argument);
}

TEST(CatmullRomSpline, FindClosestBesideBeforeAndPastTheEnds) {
  const std::vector<Eigen::Vector3d> c = WigglyControlPoints();
  const CatmullRomSpline spline(c);
  // Beside: step off the curve along a normal (perpendicular to the tangent).
  for (double s : {0.3, 1.5, 2.8, 3.6}) {
    const Eigen::Vector3d tangent = spline.Derivative(s).normalized();
    const Eigen::Vector3d normal = tangent.cross(Eigen::Vector3d::UnitZ()).normalized();
    const Eigen::Vector3d query = spline.Evaluate(s) + 0.4 * normal;
    const CatmullRomSpline::ClosestPoint closest = spline.FindClosest(query);
    EXPECT_NEAR(closest.s, s, 1e-6);
    EXPECT_NEAR(closest.distance_m, 0.4, 1e-9);
    EXPECT_EQ(closest.segment, static_cast<int>(s));
    EXPECT_NEAR(closest.u, s - static_cast<int>(s), 1e-6);
  }
  // Before the start and past the end: clamp to the end points.
  const Eigen::Vector3d before = c[1] - 5.0 * spline.Derivative(0.0).normalized();
  const CatmullRomSpline::ClosestPoint at_start = spline.FindClosest(before);
  EXPECT_EQ(at_start.s, 0.0);
  EXPECT_LT((at_start.point - c[1]).norm(), 1e-12);
  EXPECT_NEAR(at_start.distance_m, 5.0, 1e-9);
  const double s_end = spline.NumSegments();
  const Eigen::Vector3d past = c[c.size() - 2] + 7.0 * spline.Derivative(s_end).normalized();
  const CatmullRomSpline::ClosestPoint at_end = spline.FindClosest(past);
  EXPECT_EQ(at_end.s, s_end);
  EXPECT_EQ(at_end.segment, spline.NumSegments() - 1);
  EXPECT_EQ(at_end.u, 1.0);
  EXPECT_NEAR(at_end.distance_m, 7.0, 1e-9);
}

TEST(CatmullRomSpline, FindClosestIsTheGlobalMinimumOnAHairpin) {
  // A hairpin: two parallel legs 4 m apart, so most queries have a second local minimum.
  std::vector<Eigen::Vector3d> c;
  for (int k = 0; k < 6; ++k) c.emplace_back(15.0 - 3.0 * k, 0.0, 0.0);
  for (int k = 1; k < 8; ++k) {
    const double angle = -M_PI / 2 - M_PI * k / 8;
    c.emplace_back(2.0 * std::cos(angle), 2.0 + 2.0 * std::sin(angle), 0.1 * k);
  }
  for (int k = 0; k < 6; ++k) c.emplace_back(3.0 * k, 4.0, 0.8);
  const CatmullRomSpline spline(c);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> x(-6.0, 18.0), y(-3.0, 7.0), z(-1.0, 2.0);
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Vector3d query(x(rng), y(rng), z(rng));
    double brute = std::numeric_limits<double>::infinity();
    for (int k = 0; k <= 20000; ++k) {
      brute = std::min(brute, (spline.Evaluate(spline.NumSegments() * k / 20000.0) - query).norm());
    }
    const CatmullRomSpline::ClosestPoint closest = spline.FindClosest(query);
    EXPECT_LE(closest.distance_m, brute + 1e-9) << query.transpose();
    EXPECT_GT(closest.distance_m, brute - 1e-3) << query.transpose();
    EXPECT_LT((spline.Evaluate(closest.s) - closest.point).norm(), 1e-12);
  }
}

TEST(CatmullRomSpline, ConstructorRejectsTooFewOrNonFinitePoints) {
  std::vector<Eigen::Vector3d> three = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  EXPECT_THROW(CatmullRomSpline{three}, std::invalid_argument);
  std::vector<Eigen::Vector3d> with_nan = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}};
  EXPECT_NO_THROW(CatmullRomSpline{with_nan});
  with_nan[2].y() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(CatmullRomSpline{with_nan}, std::invalid_argument);
  with_nan[2].y() = std::numeric_limits<double>::infinity();
  EXPECT_THROW(CatmullRomSpline{with_nan}, std::invalid_argument);
  const CatmullRomSpline spline(WigglyControlPoints());
  EXPECT_THROW(spline.Evaluate(std::numeric_limits<double>::quiet_NaN()), std::invalid_argument);
}

// The sub-curve of ControlPointRangeNear is the whole curve near the region: same closest
// points for queries there, segment indices offset by `first`; nothing for a far region.
TEST(ControlPointRangeNear, SubCurveMatchesTheWholeCurveNearTheRegion) {
  std::vector<Eigen::Vector3d> cps;
  for (int i = 0; i < 200; ++i) {  // 600 m, gently curving
    const double x = 3.0 * i;
    cps.emplace_back(x, 0.002 * x * x / 10.0, 0.01 * std::sin(0.1 * x));
  }
  const CatmullRomSpline whole(cps);
  const std::vector<Eigen::Vector3d> region = {{300.0, 17.0, 0.0}, {330.0, 23.0, 0.0}};
  std::size_t first = 0, last = 0;
  ASSERT_TRUE(ControlPointRangeNear(cps, region, 10.0, &first, &last));
  EXPECT_LT(last - first, 25u);  // ~50 m of a 600 m lane
  EXPECT_GT(first, 0u);
  EXPECT_LT(last, cps.size() - 1);
  const CatmullRomSpline sub(
      std::vector<Eigen::Vector3d>(cps.begin() + first, cps.begin() + last + 1));
  for (double x = 295.0; x <= 335.0; x += 2.5) {
    const Eigen::Vector3d q(x, 0.002 * x * x / 10.0 + 0.7, 0.1);
    const CatmullRomSpline::ClosestPoint a = whole.FindClosest(q), b = sub.FindClosest(q);
    EXPECT_LT((a.point - b.point).norm(), 1e-9) << x;
    EXPECT_EQ(a.segment, b.segment + static_cast<int>(first)) << x;
  }
  // Far from the curve: nothing; at an end: the end is in the range.
  EXPECT_FALSE(ControlPointRangeNear(cps, {{300.0, 500.0, 0.0}}, 10.0, &first, &last));
  ASSERT_TRUE(ControlPointRangeNear(cps, {{-5.0, 0.0, 0.0}}, 10.0, &first, &last));
  EXPECT_EQ(first, 0u);
  EXPECT_GE(last - first + 1, 4u);
}

}  // namespace
}  // namespace ipm_road_mapper
