// Bounded timing series: the newest samples are kept, memory stays flat, quantiles are the
// order statistics of what is kept.
#include <gtest/gtest.h>

#include <vector>

#include "ipm_road_mapper/core/mapper/timing_series.h"

namespace ipm_road_mapper {
namespace {

TEST(TimingSeries, KeepsTheNewestSamplesWithinTheCap) {
  std::vector<int> series;
  for (int i = 0; i < 1000; ++i) AppendBounded(&series, i, 64);
  EXPECT_LE(series.size(), 64u);
  EXPECT_GE(series.size(), 32u);
  EXPECT_EQ(series.back(), 999);
  for (std::size_t i = 1; i < series.size(); ++i) EXPECT_EQ(series[i], series[i - 1] + 1);
}

TEST(TimingSeries, QuantilesAreOrderStatistics) {
  EXPECT_EQ(Quantile(std::vector<float>{}, 0.5), 0.0);
  const std::vector<double> series = {5, 1, 4, 2, 3, 10, 6, 8, 7, 9};  // 1..10 shuffled
  EXPECT_EQ(Quantile(series, 0.0), 1.0);
  EXPECT_EQ(Quantile(series, 0.5), 6.0);  // index 5 of the sorted series
  EXPECT_EQ(Quantile(series, 0.95), 10.0);
  EXPECT_EQ(Quantile(series, 1.0), 10.0);  // the maximum
  EXPECT_EQ(series.front(), 5.0);          // the input is not reordered
}

}  // namespace
}  // namespace ipm_road_mapper
