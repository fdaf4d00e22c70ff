// SeriesQuantile (series_quantile.h) gives Quantile's value (timing_series.h) at every step
// of a series that grows, is halved by AppendBounded, and is cleared, for the quantiles the
// map metadata uses and the extremes.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "ipm_road_mapper/core/mapper/series_quantile.h"
#include "ipm_road_mapper/core/mapper/timing_series.h"

namespace ipm_road_mapper {
namespace {

TEST(SeriesQuantile, EqualsQuantileAsTheSeriesGrowsIsHalvedAndCleared) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> sample(0.0f, 20.0f);
  std::uniform_int_distribution<int> burst(0, 7);
  for (double q : {0.0, 0.5, 0.95, 1.0}) {
    SCOPED_TRACE("q " + std::to_string(q));
    SeriesQuantile<float> quantile(q);
    std::vector<float> series;
    EXPECT_EQ(quantile.Update(series), 0.0);
    int halvings = 0;
    for (int step = 0; step < 400; ++step) {
      for (int k = burst(rng); k > 0; --k) {
        const std::size_t before = series.size();
        // Repeated values too (ties), and a small cap so that it halves often.
        AppendBounded(&series, k == 3 ? 5.0f : sample(rng), std::size_t{64});
        halvings += series.size() < before;
      }
      if (step == 250) series.clear();
      ASSERT_EQ(quantile.Update(series), Quantile(series, q)) << "step " << step;
    }
    EXPECT_GT(halvings, 3);
  }
}

TEST(SeriesQuantile, ASeriesReplacedByAnotherOfTheSameLengthIsReadAgain) {
  SeriesQuantile<double> median(0.5);
  EXPECT_EQ(median.Update({1.0, 2.0, 3.0}), 2.0);
  EXPECT_EQ(median.Update({7.0, 8.0, 9.0}), 8.0);  // its last sample differs: re-read
  EXPECT_EQ(median.Update({7.0, 8.0, 9.0, 10.0}), 9.0);
}

}  // namespace
}  // namespace ipm_road_mapper
