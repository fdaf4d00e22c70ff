#include "ipm_road_mapper/ros/input_gap_counter.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace ipm_road_mapper {
namespace {

constexpr std::size_t kIntervalsKept = 15;  // for the median period
constexpr std::size_t kMinIntervals = 5;    // before a stamp gap can be told
constexpr double kGapFactor = 1.5;          // an interval this many periods long is a gap

}  // namespace

double InputGapCounter::TypicalPeriod() const {
  if (intervals_.size() < kMinIntervals) return 0.0;
  std::vector<double> sorted(intervals_.begin(), intervals_.end());
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  return sorted[sorted.size() / 2];
}

void InputGapCounter::Add(std::uint32_t seq, double stamp_s) {
  ++stats_.messages;
  const bool seq_usable = last_seq_ && seq > *last_seq_;
  const bool seq_restarted = last_seq_ && *last_seq_ > 0 && seq < *last_seq_;
  if (last_stamp_ && (stamp_s < *last_stamp_ || seq_restarted)) {
    ++stats_.restarts;  // a restarted player or publisher: start over
    intervals_.clear();
    last_seq_ = seq;
    last_stamp_ = stamp_s;
    return;
  }
  if (last_stamp_) {
    const double interval = stamp_s - *last_stamp_;
    const double period = TypicalPeriod();
    bool gap = false;
    if (seq_usable) {
      const std::uint32_t missing = seq - *last_seq_ - 1;
      stats_.lost_by_seq += missing;
      gap = missing > 0;
    } else if (period > 0.0 && interval > kGapFactor * period) {
      stats_.lost_by_stamp += static_cast<std::uint64_t>(std::llround(interval / period)) - 1;
      gap = true;
    }
    if (!gap && interval > 0.0) {
      intervals_.push_back(interval);
      if (intervals_.size() > kIntervalsKept) intervals_.pop_front();
    }
    stats_.period_s = TypicalPeriod();
  }
  last_seq_ = seq;
  last_stamp_ = stamp_s;
}

}  // namespace ipm_road_mapper
