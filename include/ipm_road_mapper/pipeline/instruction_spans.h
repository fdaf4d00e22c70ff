// Instruction counts of chosen spans of a drive: a cost measure that does not move with the
// machine's load (map_from_bag --callgrind-spans, scripts/benchmark.sh --long --instructions).
//
// CPU seconds per frame vary by tens of percent between runs of the same code on a shared
// virtual machine, which is the size of the effect the long-drive benchmark looks for (does
// the last tenth cost more than the first?). Instructions executed do not. Counting them
// with callgrind over a whole 10 km drive is too slow (about 50x), so the tool runs under
// `valgrind --tool=callgrind --instr-atstart=no` (uninstrumented, about 5x) and switches
// callgrind's instrumentation on for the frames of a few stamp spans only: instrumentation
// starts right after the first frame whose stamp reaches a span's begin, and the counts are
// dumped (one callgrind file per span) right after the first frame whose stamp reaches its
// end, with the number of frames processed in between in the dump's name, so instructions per
// frame = the dump's total / that count. No ROS; the callgrind client requests are compiled
// in when <valgrind/callgrind.h> is present (Debian package valgrind).
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

namespace ipm_road_mapper {

// One span of frame stamps, [begin_s, end_s) in the bag's clock.
struct StampSpan {
  double begin_s = 0.0;
  double end_s = 0.0;
};

// Parses "t0:t1,t2:t3,..." (seconds; finite, t0 < t1, spans in increasing order and not
// overlapping). Throws std::invalid_argument naming the offending part.
std::vector<StampSpan> ParseStampSpans(const std::string& text);

// What the spans do to the profiler: start counting, and dump the counts under a name and
// stop counting. Injected so the state machine is tested without valgrind.
struct InstructionCounterHooks {
  std::function<void()> start;
  std::function<void(const std::string& dump_name)> dump_and_stop;
};

// The callgrind client requests (CALLGRIND_ZERO_STATS + CALLGRIND_START_INSTRUMENTATION;
// CALLGRIND_DUMP_STATS_AT + CALLGRIND_STOP_INSTRUMENTATION). Returns an empty string and
// fills *hooks when the process runs under valgrind and the requests were compiled in; else
// the reason it cannot count.
std::string CallgrindHooks(InstructionCounterHooks* hooks);

// Switches the counter on and off over the spans as frames are processed (file comment).
class InstructionSpans {
 public:
  InstructionSpans(std::vector<StampSpan> spans, InstructionCounterHooks hooks);

  // Call after each processed frame with its stamp (stamps non-decreasing).
  void OnFrameDone(double stamp);

  // Dumps a span still open at the end of the drive (its frames so far); idempotent.
  void Finish();

  // "span <k> frames <n> stamps <first>-<last>": the dump name of span k (exposed for tests
  // and for scripts/irm_bench/long_stats.py, which parses it).
  static std::string DumpName(std::size_t span, std::size_t frames, double first_stamp,
                              double last_stamp);

  // Spans dumped so far, and spans skipped because no frame fell inside them.
  std::size_t dumped() const { return dumped_; }
  std::size_t skipped() const { return skipped_; }

 private:
  void Dump();

  std::vector<StampSpan> spans_;
  InstructionCounterHooks hooks_;
  std::size_t next_ = 0;  // the span to start (or the open one while active_)
  bool active_ = false;
  std::size_t frames_ = 0;    // frames processed since the open span started
  double first_stamp_ = 0.0;  // stamp of the frame after which counting started
  double last_stamp_ = 0.0;
  std::size_t dumped_ = 0;
  std::size_t skipped_ = 0;
};

}  // namespace ipm_road_mapper
