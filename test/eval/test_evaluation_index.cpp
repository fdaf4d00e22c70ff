// The evaluator's building blocks (evaluation.h): the polyline distance index against a
// brute-force search, and the error summary on known values.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "ipm_road_mapper/eval/evaluation.h"

namespace ipm_road_mapper {
namespace {

TEST(PolylineDistanceIndex, MatchesBruteForce) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> coordinate(-20.0, 20.0), step(-0.3, 0.3);
  std::vector<std::vector<Eigen::Vector3d>> polylines(5);
  for (auto& polyline : polylines) {
    Eigen::Vector3d p(coordinate(rng), coordinate(rng), 0.1 * coordinate(rng));
    for (int k = 0; k < 200; ++k) {
      polyline.push_back(p);
      p += Eigen::Vector3d(0.4 + step(rng), step(rng), 0.1 * step(rng));
      if (k == 100) p.x() += 5.0;  // a gap: not joined
    }
  }
  polylines.push_back({Eigen::Vector3d(0.0, 0.0, 0.0)});  // a lone point
  const PolylineDistanceIndex index(polylines, 1.0);
  for (int q = 0; q < 500; ++q) {
    const Eigen::Vector3d query(coordinate(rng), coordinate(rng), 0.1 * coordinate(rng));
    double best = std::numeric_limits<double>::infinity();
    for (const auto& polyline : polylines) {
      for (std::size_t k = 0; k < polyline.size(); ++k) {
        best = std::min(best, (polyline[k] - query).norm());
        if (k + 1 == polyline.size() || (polyline[k + 1] - polyline[k]).norm() > 1.0) continue;
        const Eigen::Vector3d ab = polyline[k + 1] - polyline[k];
        const double t = std::clamp((query - polyline[k]).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
        best = std::min(best, (polyline[k] + t * ab - query).norm());
      }
    }
    const PolylineDistanceIndex::Nearest nearest = index.Query(query);
    ASSERT_NEAR(nearest.distance_m, best, 1e-12) << "query " << q;
    EXPECT_NEAR((nearest.point - query).norm(), best, 1e-12);
  }
  EXPECT_EQ(PolylineDistanceIndex({}, 1.0).Query(Eigen::Vector3d::Zero()).polyline, -1);
}

TEST(Summarize, KnownValues) {
  const ErrorSummary s = Summarize({1.0, 2.0, 3.0, 4.0});
  EXPECT_EQ(s.count, 4);
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
  EXPECT_DOUBLE_EQ(s.stddev, std::sqrt(1.25));
  EXPECT_DOUBLE_EQ(s.median, 2.5);
  EXPECT_DOUBLE_EQ(s.max, 4.0);
  EXPECT_DOUBLE_EQ(s.rmse, std::sqrt(7.5));
  EXPECT_TRUE(std::isnan(Summarize({}).mean));
}

}  // namespace
}  // namespace ipm_road_mapper
