// Skip reasons: every reason has a distinct counter key that parses back to it, and the
// Mapper counts a reason given as text under the same key as the enum.
#include <gtest/gtest.h>

#include <set>

#include "common/road_scene.h"
#include "ipm_road_mapper/core/mapper/skip_reason.h"

namespace ipm_road_mapper {
namespace {

TEST(SkipReason, KeysAreDistinctAndParseBack) {
  std::set<std::string> keys;
  for (int r = static_cast<int>(SkipReason::kBadStamp);
       r <= static_cast<int>(SkipReason::kNoCameraInfo); ++r) {
    const SkipReason reason = static_cast<SkipReason>(r);
    const std::string key = ToString(reason);
    EXPECT_NE(key, "unknown") << r;
    EXPECT_TRUE(keys.insert(key).second) << key;
    ASSERT_TRUE(ParseSkipReason(key).has_value()) << key;
    EXPECT_EQ(*ParseSkipReason(key), reason);
  }
  EXPECT_FALSE(ParseSkipReason("Bad_Mask").has_value());
  EXPECT_EQ(SkipText(SkipReason::kBadMask, "640x480"), "bad_mask: 640x480");
  EXPECT_EQ(SkipText(SkipReason::kReset, ""), "reset");
}

TEST(SkipReason, TheMapperCountsTextAndEnumAlike) {
  MapperOptions options;
  options.backend.enabled = false;
  Mapper mapper(options, test::TestClasses(), test::TestExtrinsic());
  mapper.CountSkipped(SkipReason::kNoOdometry);
  mapper.CountSkipped("no_odometry: frame at 12.5 s: no odometry received");
  mapper.CountSkipped("something_new: a layer's own reason");  // counted, not lost
  EXPECT_EQ(mapper.counters().frames_skipped.at("no_odometry"), 2u);
  EXPECT_EQ(mapper.counters().frames_skipped.at("something_new"), 1u);
  EXPECT_EQ(mapper.counters().frames_received, 3u);
  std::string reason;
  FrameInput in = test::RoadFrame(100.0, 0.0);
  in.mask = cv::Mat::zeros(10, 10, CV_16UC1);
  EXPECT_EQ(mapper.ProcessFrame(in, &reason), FrameStatus::kSkipped);
  EXPECT_EQ(reason.rfind("bad_mask: ", 0), 0u) << reason;
  EXPECT_EQ(mapper.counters().frames_skipped.at("bad_mask"), 1u);
}

}  // namespace
}  // namespace ipm_road_mapper
