#include "ipm_road_mapper/pipeline/instruction_spans.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <utility>

#if __has_include(<valgrind/callgrind.h>)
#include <valgrind/callgrind.h>
#define IRM_HAVE_CALLGRIND 1
#endif

namespace ipm_road_mapper {

namespace {

double ParseSeconds(const std::string& text, const std::string& part) {
  std::size_t used = 0;
  double value = 0.0;
  try {
    value = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (text.empty() || used != text.size() || !std::isfinite(value)) {
    throw std::invalid_argument("span '" + part + "': '" + text + "' is not a finite number of s");
  }
  return value;
}

}  // namespace

std::vector<StampSpan> ParseStampSpans(const std::string& text) {
  std::vector<StampSpan> spans;
  std::size_t from = 0;
  while (from <= text.size()) {
    const std::size_t comma = std::min(text.find(',', from), text.size());
    const std::string part = text.substr(from, comma - from);
    from = comma + 1;
    const std::size_t colon = part.find(':');
    if (colon == std::string::npos) {
      throw std::invalid_argument("span '" + part + "': expected <begin_s>:<end_s>");
    }
    StampSpan span;
    span.begin_s = ParseSeconds(part.substr(0, colon), part);
    span.end_s = ParseSeconds(part.substr(colon + 1), part);
    if (!(span.begin_s < span.end_s)) {
      throw std::invalid_argument("span '" + part + "': its begin is not before its end");
    }
    if (!spans.empty() && span.begin_s < spans.back().end_s) {
      throw std::invalid_argument("span '" + part +
                                  "': begins before the previous span ends (spans in order)");
    }
    spans.push_back(span);
  }
  if (spans.empty()) throw std::invalid_argument("no span in '" + text + "'");
  return spans;
}

std::string CallgrindHooks(InstructionCounterHooks* hooks) {
#ifdef IRM_HAVE_CALLGRIND
  if (!RUNNING_ON_VALGRIND) {
    return "not running under valgrind (run: valgrind --tool=callgrind --instr-atstart=no "
           "map_from_bag ...)";
  }
  hooks->start = [] {
    CALLGRIND_START_INSTRUMENTATION;
    CALLGRIND_ZERO_STATS;
  };
  hooks->dump_and_stop = [](const std::string& dump_name) {
    CALLGRIND_DUMP_STATS_AT(dump_name.c_str());
    CALLGRIND_STOP_INSTRUMENTATION;
  };
  return "";
#else
  (void)hooks;
  return "built without <valgrind/callgrind.h> (install the Debian package valgrind and "
         "rebuild)";
#endif
}

InstructionSpans::InstructionSpans(std::vector<StampSpan> spans, InstructionCounterHooks hooks)
    : spans_(std::move(spans)), hooks_(std::move(hooks)) {}

void InstructionSpans::OnFrameDone(double stamp) {
  if (active_) {
    if (frames_ == 0) first_stamp_ = stamp;
    ++frames_;
    last_stamp_ = stamp;
    if (stamp >= spans_[next_].end_s) Dump();
  }
  if (active_) return;
  while (next_ < spans_.size() && stamp >= spans_[next_].end_s) {  // no frame fell inside
    ++skipped_;
    ++next_;
  }
  if (next_ < spans_.size() && stamp >= spans_[next_].begin_s) {
    hooks_.start();
    active_ = true;
    frames_ = 0;
  }
}

void InstructionSpans::Finish() {
  if (active_) Dump();
}

std::string InstructionSpans::DumpName(std::size_t span, std::size_t frames, double first_stamp,
                                       double last_stamp) {
  char text[128];
  std::snprintf(text, sizeof(text), "span %zu frames %zu stamps %.3f-%.3f", span, frames,
                first_stamp, last_stamp);
  return text;
}

void InstructionSpans::Dump() {
  hooks_.dump_and_stop(DumpName(next_, frames_, first_stamp_, last_stamp_));
  active_ = false;
  ++dumped_;
  ++next_;
}

}  // namespace ipm_road_mapper
