// Process statistics: CPU time grows with work, the resident set grows with touched memory,
// the process start lies before now, and the stats CSV has its header and one row per frame.
#include <gtest/gtest.h>
#include <stdlib.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "ipm_road_mapper/pipeline/process_stats.h"

namespace ipm_road_mapper {
namespace {

TEST(ProcessStatsTest, CpuTimeGrowsWithWork) {
  const double before_s = ProcessCpuSeconds();
  ASSERT_GE(before_s, 0.0);
  volatile double sink = 0.0;
  for (int i = 0; i < 20000000; ++i) sink = sink + 1e-9 * i;
  EXPECT_GT(ProcessCpuSeconds(), before_s + 1e-3);
}

TEST(ProcessStatsTest, ResidentSetGrowsWithTouchedMemory) {
  const long before_kb = ResidentSetKb();
  ASSERT_GT(before_kb, 0);
  std::vector<char> block(64 << 20, 1);  // 64 MB, every page written
  EXPECT_GT(ResidentSetKb(), before_kb + 32 * 1024);
  EXPECT_EQ(block[12345], 1);
}

TEST(ProcessStatsTest, ProcessStartIsBeforeNowAndRecent) {
  const double first_s = SecondsSinceProcessStart();
  EXPECT_GE(first_s, 0.0);
  EXPECT_LT(first_s, 600.0) << "a test process is not that old";
  usleep(50000);
  const double second_s = SecondsSinceProcessStart();
  EXPECT_GT(second_s, first_s + 0.04);
  EXPECT_LT(second_s, first_s + 1.0);
}

TEST(FrameStatsWriterTest, HeaderAndOneRowPerFrame) {
  char pattern[] = "/tmp/irm_stats_XXXXXX.csv";
  const int fd = mkstemps(pattern, 4);
  ASSERT_GE(fd, 0);
  close(fd);
  FrameStatsWriter writer(pattern);
  writer.Add(0, 1700000000.1);
  writer.Add(1, 1700000000.2);
  writer.Close();
  std::ifstream in(pattern);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  std::remove(pattern);
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines[0], "frame,stamp,cpu_s,rss_kb");
  EXPECT_EQ(lines[1].rfind("0,1700000000.100000,", 0), 0u) << lines[1];
  EXPECT_EQ(lines[2].rfind("1,1700000000.200000,", 0), 0u) << lines[2];
  double cpu_s = -1.0;
  long rss_kb = -1;
  ASSERT_EQ(std::sscanf(lines[2].c_str(), "1,%*f,%lf,%ld", &cpu_s, &rss_kb), 2) << lines[2];
  EXPECT_GT(cpu_s, 0.0);
  EXPECT_GT(rss_kb, 0);
}

TEST(FrameStatsWriterTest, UnwritablePathThrows) {
  EXPECT_THROW(FrameStatsWriter("/nonexistent_dir/stats.csv"), std::runtime_error);
}

}  // namespace
}  // namespace ipm_road_mapper
