// One quantile of a timing series (timing_series.h) kept up to date as the series grows, so
// that a repeated export costs the samples appended since the last one, not the series'
// length: the same value as Quantile(series, q), from two heaps split at the quantile's
// rank. A series that shrank (AppendBounded dropped its oldest half, or it was cleared) is
// read again from the start.
#pragma once

#include <algorithm>
#include <cstddef>
#include <functional>
#include <queue>
#include <vector>

namespace ipm_road_mapper {

template <typename T>
class SeriesQuantile {
 public:
  // The q-quantile (0..1; 1 = the maximum), as Quantile's.
  explicit SeriesQuantile(double q) : q_(q) {}

  // Quantile(series, q), reading only the samples appended since the last call (or all of
  // them when the series is not the one read before plus new samples).
  double Update(const std::vector<T>& series) {
    const bool continued =
        consumed_ <= series.size() && (consumed_ == 0 || series[consumed_ - 1] == last_consumed_);
    if (!continued) Clear();
    for (std::size_t i = consumed_; i < series.size(); ++i) Insert(series[i]);
    consumed_ = series.size();
    if (consumed_ > 0) last_consumed_ = series[consumed_ - 1];
    return lower_.empty() ? 0.0 : static_cast<double>(lower_.top());
  }

 private:
  // Adds one sample; `lower_` keeps the rank + 1 smallest samples (the answer on top).
  void Insert(T value) {
    if (!lower_.empty() && value < lower_.top()) {
      lower_.push(value);
    } else {
      upper_.push(value);
    }
    const std::size_t n = lower_.size() + upper_.size();
    const std::size_t rank = std::min(n - 1, static_cast<std::size_t>(q_ * static_cast<double>(n)));
    while (lower_.size() > rank + 1) {
      upper_.push(lower_.top());
      lower_.pop();
    }
    while (lower_.size() < rank + 1) {
      lower_.push(upper_.top());
      upper_.pop();
    }
  }

  void Clear() {
    lower_ = decltype(lower_)();
    upper_ = decltype(upper_)();
    consumed_ = 0;
  }

  double q_;
  std::priority_queue<T> lower_;                                   // max on top
  std::priority_queue<T, std::vector<T>, std::greater<T>> upper_;  // min on top
  std::size_t consumed_ = 0;  // samples of the series read so far
  T last_consumed_{};         // the last of them
};

}  // namespace ipm_road_mapper
