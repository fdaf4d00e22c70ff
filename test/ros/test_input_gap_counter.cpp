// InputGapCounter: messages lost before the callback, told by header.seq jumps or, without a
// usable seq, by stamp gaps; restarts are not losses.
#include <gtest/gtest.h>

#include "ipm_road_mapper/ros/input_gap_counter.h"

namespace ipm_road_mapper {
namespace {

TEST(InputGapCounter, SeqJumpsCountTheMissingMessages) {
  InputGapCounter counter;
  for (std::uint32_t seq : {1u, 2u, 3u, 7u, 8u, 10u}) counter.Add(seq, 0.05 * seq);
  EXPECT_EQ(counter.stats().messages, 6u);
  EXPECT_EQ(counter.stats().lost_by_seq, 3u + 1u);
  EXPECT_EQ(counter.stats().lost_by_stamp, 0u);
}

TEST(InputGapCounter, WithoutSeqStampGapsCount) {
  InputGapCounter counter;
  double t = 100.0;
  for (int i = 0; i < 10; ++i) counter.Add(0, t += 0.05);  // 20 Hz, seq always 0 (a bag)
  EXPECT_EQ(counter.stats().lost(), 0u);
  EXPECT_NEAR(counter.stats().period_s, 0.05, 1e-9);
  counter.Add(0, t += 0.15);  // two missing
  EXPECT_EQ(counter.stats().lost_by_stamp, 2u);
  counter.Add(0, t += 0.06);  // jitter is not a loss
  counter.Add(0, t += 0.04);
  EXPECT_EQ(counter.stats().lost_by_stamp, 2u);
  // A restarted player: stamps go back, start over without counting.
  counter.Add(0, 100.0);
  EXPECT_EQ(counter.stats().restarts, 1u);
  counter.Add(0, 105.0);  // the period is not known yet after a restart
  EXPECT_EQ(counter.stats().lost(), 2u);
}

}  // namespace
}  // namespace ipm_road_mapper
