// BagReadLossTracker: consecutive unreadable messages form one span, a readable one ends it;
// masks and the first error are counted; the stderr line, the summary text and the map.json
// metadata say the same spans relative to the bag's start.
#include <gtest/gtest.h>

#include <string>

#include "ipm_road_mapper/ros/bag_read_loss.h"

namespace ipm_road_mapper {
namespace {

constexpr double kBegin = 1700000000.0;

TEST(BagReadLoss, NothingLost) {
  BagReadLossTracker tracker;
  tracker.Read();
  EXPECT_TRUE(tracker.loss().empty());
  EXPECT_EQ(FormatLostSpans(tracker.loss(), kBegin), "none");
  EXPECT_EQ(LostSpansLine(tracker.loss(), kBegin), "");
  const nlohmann::json json = LostSpansToJson(tracker.loss(), kBegin);
  EXPECT_EQ(json["messages"], 0);
  EXPECT_TRUE(json["spans"].empty());
}

TEST(BagReadLoss, ConsecutiveLossesAreOneSpan) {
  BagReadLossTracker tracker;
  tracker.Read();
  tracker.Lost(kBegin + 12.35, false, "ROSLZ4_DATA_ERROR");
  tracker.Lost(kBegin + 13.0, true, "second error");
  tracker.Lost(kBegin + 14.80, true, "third error");
  tracker.Read();
  tracker.Read();
  tracker.Lost(kBegin + 20.0, true, "fourth error");
  const BagReadLoss& loss = tracker.loss();
  ASSERT_EQ(loss.spans.size(), 2u);
  EXPECT_EQ(loss.messages, 4u);
  EXPECT_EQ(loss.masks, 3u);
  EXPECT_EQ(loss.spans[0].messages, 3u);
  EXPECT_EQ(loss.spans[1].messages, 1u);
  EXPECT_EQ(loss.first_error, "ROSLZ4_DATA_ERROR");
  EXPECT_EQ(FormatLostSpans(loss, kBegin), "12.35-14.80 s, 20.00-20.00 s");
  EXPECT_EQ(LostSpansLine(loss, kBegin),
            "map_from_bag: lost 12.35-14.80 s, 20.00-20.00 s of the bag (2 unreadable spans: 4 "
            "messages, 3 masks; first error: ROSLZ4_DATA_ERROR)");
  const nlohmann::json json = LostSpansToJson(loss, kBegin);
  EXPECT_EQ(json["messages"], 4);
  EXPECT_EQ(json["masks"], 3);
  ASSERT_EQ(json["spans"].size(), 2u);
  EXPECT_NEAR(json["spans"][0]["begin_s"].get<double>(), 12.35, 1e-6);
  EXPECT_NEAR(json["spans"][0]["end_s"].get<double>(), 14.80, 1e-6);
  EXPECT_NEAR(json["spans"][1]["begin_stamp"].get<double>(), kBegin + 20.0, 1e-6);
  EXPECT_EQ(json["first_error"], "ROSLZ4_DATA_ERROR");
}

TEST(BagReadLoss, OneSpanIsSingular) {
  BagReadLossTracker tracker;
  tracker.Lost(kBegin + 1.0, false, "e");
  EXPECT_NE(LostSpansLine(tracker.loss(), kBegin).find("(1 unreadable span: 1 messages"),
            std::string::npos)
      << LostSpansLine(tracker.loss(), kBegin);
}

TEST(BagReadLoss, LongListsAreCutInTheText) {
  BagReadLossTracker tracker;
  for (int k = 0; k < 13; ++k) {
    tracker.Lost(kBegin + k, false, "e");
    tracker.Read();
  }
  const std::string text = FormatLostSpans(tracker.loss(), kBegin);
  EXPECT_NE(text.find("9.00-9.00 s and 3 more"), std::string::npos) << text;
  EXPECT_EQ(text.find("10.00-10.00 s"), std::string::npos) << text;
  EXPECT_EQ(LostSpansToJson(tracker.loss(), kBegin)["spans"].size(), 13u);
}

}  // namespace
}  // namespace ipm_road_mapper
