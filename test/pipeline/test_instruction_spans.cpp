#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "ipm_road_mapper/pipeline/instruction_spans.h"

namespace ipm_road_mapper {
namespace {

// Records what the spans asked of the profiler, in order ("start", "dump <name>").
struct Recorder {
  std::vector<std::string> calls;
  InstructionCounterHooks Hooks() {
    return {[this] { calls.push_back("start"); },
            [this](const std::string& name) { calls.push_back("dump " + name); }};
  }
};

TEST(InstructionSpans, ParsesSpansInOrder) {
  const std::vector<StampSpan> spans = ParseStampSpans("1.5:3,10:12.25");
  ASSERT_EQ(spans.size(), 2u);
  EXPECT_DOUBLE_EQ(spans[0].begin_s, 1.5);
  EXPECT_DOUBLE_EQ(spans[0].end_s, 3.0);
  EXPECT_DOUBLE_EQ(spans[1].begin_s, 10.0);
  EXPECT_DOUBLE_EQ(spans[1].end_s, 12.25);
}

TEST(InstructionSpans, RejectsMalformedSpans) {
  for (const char* bad :
       {"", "1", "1:", ":2", "a:2", "1:2x", "3:2", "2:2", "1:3,2:4", "1:nan", "1:inf", "1:2,"}) {
    EXPECT_THROW(ParseStampSpans(bad), std::invalid_argument) << "'" << bad << "'";
  }
}

// Frames every 0.1 s; span [1.0, 1.5): counting starts after the frame at 1.0, and the
// dump follows the frame at 1.5, so it holds the 5 frames 1.1 .. 1.5.
TEST(InstructionSpans, CountsTheFramesBetweenStartAndDump) {
  Recorder recorder;
  InstructionSpans spans({{1.0, 1.5}, {2.0, 2.2}}, recorder.Hooks());
  for (int k = 0; k <= 30; ++k) spans.OnFrameDone(0.1 * k + 1e-9);
  spans.Finish();
  ASSERT_EQ(recorder.calls.size(), 4u);
  EXPECT_EQ(recorder.calls[0], "start");
  EXPECT_EQ(recorder.calls[1], "dump " + InstructionSpans::DumpName(0, 5, 1.1, 1.5));
  EXPECT_EQ(recorder.calls[2], "start");
  EXPECT_EQ(recorder.calls[3], "dump " + InstructionSpans::DumpName(1, 2, 2.1, 2.2));
  EXPECT_EQ(spans.dumped(), 2u);
  EXPECT_EQ(spans.skipped(), 0u);
}

TEST(InstructionSpans, SkipsSpansNoFrameFellInAndDumpsAnOpenSpanAtTheEnd) {
  Recorder recorder;
  // Frames at 0, 1, 2, ...: no frame in [1.2, 1.4); the last span is still open at the end.
  InstructionSpans spans({{1.2, 1.4}, {3.0, 100.0}}, recorder.Hooks());
  for (int k = 0; k <= 5; ++k) spans.OnFrameDone(k);
  EXPECT_EQ(spans.skipped(), 1u);
  spans.Finish();
  spans.Finish();  // idempotent
  ASSERT_EQ(recorder.calls.size(), 2u);
  EXPECT_EQ(recorder.calls[0], "start");
  EXPECT_EQ(recorder.calls[1], "dump " + InstructionSpans::DumpName(1, 2, 4.0, 5.0));
}

TEST(InstructionSpans, DumpNameIsWhatTheBenchmarkParses) {
  // scripts/irm_bench/long_stats.py reads "span (\d+) frames (\d+)".
  EXPECT_EQ(InstructionSpans::DumpName(2, 610, 12.5, 73.4),
            "span 2 frames 610 stamps 12.500-73.400");
}

TEST(InstructionSpans, CallgrindHooksRefuseOutsideValgrind) {
  InstructionCounterHooks hooks;
  const std::string reason = CallgrindHooks(&hooks);  // gtest does not run under valgrind
  EXPECT_FALSE(reason.empty());
  EXPECT_FALSE(hooks.start);
}

}  // namespace
}  // namespace ipm_road_mapper
