#include "ipm_road_mapper/ros/bag_read_loss.h"

#include <cstdio>

namespace ipm_road_mapper {

void BagReadLossTracker::Lost(double bag_time_s, bool is_mask, const std::string& error) {
  if (!in_span_) {
    loss_.spans.push_back({bag_time_s, bag_time_s, 0});
    in_span_ = true;
  }
  LostSpan& span = loss_.spans.back();
  span.end_s = bag_time_s;
  ++span.messages;
  ++loss_.messages;
  if (is_mask) ++loss_.masks;
  if (loss_.first_error.empty()) loss_.first_error = error;
}

std::string FormatLostSpans(const BagReadLoss& loss, double bag_begin_s) {
  if (loss.spans.empty()) return "none";
  std::string text;
  for (std::size_t k = 0; k < loss.spans.size(); ++k) {
    if (k == kMaxSpansInText) {
      text += " and " + std::to_string(loss.spans.size() - k) + " more";
      break;
    }
    const LostSpan& span = loss.spans[k];
    char one[64];
    std::snprintf(one, sizeof(one), "%.2f-%.2f s", span.begin_s - bag_begin_s,
                  span.end_s - bag_begin_s);
    text += (text.empty() ? "" : ", ") + std::string(one);
  }
  return text;
}

std::string LostSpansLine(const BagReadLoss& loss, double bag_begin_s) {
  if (loss.empty()) return "";
  const std::size_t n = loss.spans.size();
  return "map_from_bag: lost " + FormatLostSpans(loss, bag_begin_s) + " of the bag (" +
         std::to_string(n) + " unreadable span" + (n == 1 ? "" : "s") + ": " +
         std::to_string(loss.messages) + " messages, " + std::to_string(loss.masks) +
         " masks; first error: " + loss.first_error + ")";
}

nlohmann::json LostSpansToJson(const BagReadLoss& loss, double bag_begin_s) {
  nlohmann::json spans = nlohmann::json::array();
  for (const LostSpan& span : loss.spans) {
    spans.push_back({{"begin_s", span.begin_s - bag_begin_s},
                     {"end_s", span.end_s - bag_begin_s},
                     {"messages", span.messages},
                     {"begin_stamp", span.begin_s},
                     {"end_stamp", span.end_s}});
  }
  return {{"messages", loss.messages},
          {"masks", loss.masks},
          {"spans", spans},
          {"first_error", loss.first_error}};
}

}  // namespace ipm_road_mapper
