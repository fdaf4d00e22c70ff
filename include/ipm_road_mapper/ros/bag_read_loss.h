// What a damaged bag could not deliver while it was streamed: its mapper-input messages that
// could not be read (a corrupt chunk), grouped into the time spans of the bag they covered, so
// map_from_bag can say which part of the drive is missing from the map. Offline only; no
// ROS types, so it is tested without a bag.
#pragma once

#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace ipm_road_mapper {

// Consecutive unreadable messages (no readable one between them, in bag order).
struct LostSpan {
  double begin_s = 0.0;  // record time of its first lost message, s
  double end_s = 0.0;    // record time of its last lost message, s
  std::size_t messages = 0;
};

// Every message lost while a bag was streamed.
struct BagReadLoss {
  std::vector<LostSpan> spans;  // in bag order
  std::size_t messages = 0;     // lost messages of the mapper's topics
  std::size_t masks = 0;        // of them, masks (each a frame lost)
  std::string first_error;      // the first read error, e.g. "ROSLZ4_DATA_ERROR ..."

  bool empty() const { return messages == 0; }
};

// Builds a BagReadLoss from the messages of a stream, in bag order.
class BagReadLossTracker {
 public:
  // A message that could not be read, recorded at `bag_time_s`.
  void Lost(double bag_time_s, bool is_mask, const std::string& error);
  // A message that was read: the current span (if any) ends.
  void Read() { in_span_ = false; }

  const BagReadLoss& loss() const { return loss_; }

 private:
  BagReadLoss loss_;
  bool in_span_ = false;
};

// Spans listed in the text (the stderr line, the summary); map.json has all of them.
constexpr std::size_t kMaxSpansInText = 10;

// "12.35-14.80 s, 20.00-20.10 s" with times relative to `bag_begin_s`, the first
// kMaxSpansInText spans then " and N more"; "none" when empty.
std::string FormatLostSpans(const BagReadLoss& loss, double bag_begin_s);

// The one stderr line about the loss, e.g. "map_from_bag: lost 12.35-14.80 s of the bag (1
// unreadable span: 12 messages, 3 masks; first error: ...)"; empty when nothing was lost.
std::string LostSpansLine(const BagReadLoss& loss, double bag_begin_s);

// For map.json metadata: {"messages", "masks", "spans": [{"begin_s", "end_s", "messages",
// "begin_stamp", "end_stamp"}], "first_error"}; span times relative to the bag begin, stamps
// absolute (s).
nlohmann::json LostSpansToJson(const BagReadLoss& loss, double bag_begin_s);

}  // namespace ipm_road_mapper
