// ProgressMeter: the line's content, and the throttling of the non-interactive mode (one
// line per 10%, then the final one).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>

#include "ipm_road_mapper/pipeline/progress_meter.h"

namespace ipm_road_mapper {
namespace {

std::string ReadAll(std::FILE* file) {
  std::rewind(file);
  std::string text;
  char buffer[256];
  while (std::fgets(buffer, sizeof(buffer), file)) text += buffer;
  return text;
}

int CountLines(const std::string& text) {
  int lines = 0;
  for (char c : text) lines += c == '\n';
  return lines;
}

TEST(ProgressMeterTest, FormatShowsCountRateAndEta) {
  const std::string line = ProgressMeter::Format(50, 200, "frames", 5.0);
  EXPECT_NE(line.find("50/200 frames 25%"), std::string::npos) << line;
  EXPECT_NE(line.find("10.0 frames/s"), std::string::npos) << line;
  EXPECT_NE(line.find("ETA 0:15"), std::string::npos) << line;
  EXPECT_EQ(line.rfind("[######------------------]", 0), 0u) << line;
}

TEST(ProgressMeterTest, FormatAtTheEndAndWithoutProgress) {
  EXPECT_NE(ProgressMeter::Format(200, 200, "frames", 3725.0).find("took 1:02:05"),
            std::string::npos);
  EXPECT_NE(ProgressMeter::Format(0, 200, "frames", 0.0).find("ETA ?"), std::string::npos);
  EXPECT_NE(ProgressMeter::Format(0, 0, "frames", 1.0).find("100%"), std::string::npos);
}

TEST(ProgressMeterTest, NonInteractiveWritesALinePerTenPercent) {
  std::FILE* file = std::tmpfile();
  ASSERT_NE(file, nullptr);
  {
    ProgressMeter meter(1000, "frames", file, /*interactive=*/false);
    for (std::size_t i = 1; i <= 1000; ++i) meter.Update(i);
    meter.Finish();
    meter.Finish();  // idempotent
  }
  const std::string text = ReadAll(file);
  std::fclose(file);
  EXPECT_EQ(CountLines(text), 11) << text;  // 0%, 10%, ..., 90% and the final line
  EXPECT_EQ(text.find('\r'), std::string::npos);
  EXPECT_NE(text.find("1000/1000 frames 100%"), std::string::npos) << text;
}

TEST(ProgressMeterTest, InteractiveRedrawsInPlaceAndIsThrottled) {
  std::FILE* file = std::tmpfile();
  ASSERT_NE(file, nullptr);
  ProgressMeter meter(1000, "frames", file, /*interactive=*/true);
  for (std::size_t i = 1; i <= 1000; ++i) meter.Update(i);  // far faster than 0.2 s
  meter.Finish();
  const std::string text = ReadAll(file);
  std::fclose(file);
  EXPECT_EQ(CountLines(text), 1) << "one line, redrawn with \\r";
  EXPECT_LE(std::count(text.begin(), text.end(), '\r'), 3) << "throttled";
  EXPECT_NE(text.find("1000/1000 frames 100%"), std::string::npos);
}

}  // namespace
}  // namespace ipm_road_mapper
