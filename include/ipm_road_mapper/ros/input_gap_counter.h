// Counts the messages of one input stream that never reached its callback (dropped from a
// full subscriber queue, or lost on the way), from the headers of those that did:
// - header.seq: when the publisher numbers its messages (seq grows), a jump from s to s + k
//   means k - 1 lost messages;
// - stamps: when seq carries no information (0, or not increasing, as after a bag loop),
//   an interval of more than 1.5 typical periods (the median of the last intervals)
//   means round(interval / period) - 1 lost messages.
// A stamp going backwards (a restarted player) starts over without counting. Pure and
// unit-tested; one instance per stream, called from that stream's callback only.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <optional>

namespace ipm_road_mapper {

// What the counter saw so far.
struct InputGapStats {
  std::uint64_t messages = 0;
  std::uint64_t lost_by_seq = 0;    // counted from header.seq jumps
  std::uint64_t lost_by_stamp = 0;  // counted from stamp gaps (streams without a usable seq)
  std::uint64_t restarts = 0;       // stamps or seq going backwards
  double period_s = 0.0;            // the typical interval (0 until known)
  std::uint64_t lost() const { return lost_by_seq + lost_by_stamp; }
};

class InputGapCounter {
 public:
  // One arrival, with its header's seq and stamp (s).
  void Add(std::uint32_t seq, double stamp_s);
  const InputGapStats& stats() const { return stats_; }

 private:
  double TypicalPeriod() const;

  InputGapStats stats_;
  std::optional<std::uint32_t> last_seq_;
  std::optional<double> last_stamp_;
  std::deque<double> intervals_;  // the newest intervals that were not gaps
};

}  // namespace ipm_road_mapper
