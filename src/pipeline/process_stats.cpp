#include "ipm_road_mapper/pipeline/process_stats.h"

#include <time.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <sstream>
#include <stdexcept>

namespace ipm_road_mapper {
namespace {

// When this library was loaded: the fallback origin of SecondsSinceProcessStart.
const std::chrono::steady_clock::time_point kLoaded = std::chrono::steady_clock::now();

double ClockSeconds(clockid_t clock) {
  timespec t{};
  if (clock_gettime(clock, &t) != 0) return -1.0;
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// Field 22 of /proc/self/stat (starttime, clock ticks after boot), or -1. The fields are
// counted after the last ')', since the command name (field 2) may hold spaces.
long long StartTimeTicks() {
  std::ifstream in("/proc/self/stat");
  std::string text;
  std::getline(in, text);
  const std::size_t name_end = text.rfind(')');
  if (name_end == std::string::npos) return -1;
  std::istringstream fields(text.substr(name_end + 1));
  std::string field;
  for (int index = 3; index <= 22; ++index) {
    if (!(fields >> field)) return -1;
  }
  try {
    return std::stoll(field);
  } catch (const std::exception&) {
    return -1;
  }
}

}  // namespace

double ProcessCpuSeconds() { return ClockSeconds(CLOCK_PROCESS_CPUTIME_ID); }

long ResidentSetKb() {
  std::ifstream in("/proc/self/statm");
  long size_pages = 0, resident_pages = 0;
  if (!(in >> size_pages >> resident_pages)) return -1;
  return resident_pages * (sysconf(_SC_PAGESIZE) / 1024);
}

double SecondsSinceProcessStart() {
  const long long ticks = StartTimeTicks();
  const long ticks_per_s = sysconf(_SC_CLK_TCK);
  const double now_s = ClockSeconds(CLOCK_BOOTTIME);
  if (ticks >= 0 && ticks_per_s > 0 && now_s >= 0.0) {
    const double elapsed_s = now_s - static_cast<double>(ticks) / ticks_per_s;
    if (elapsed_s >= 0.0) return elapsed_s;
  }
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - kLoaded).count();
}

FrameStatsWriter::FrameStatsWriter(const std::string& path) : path_(path), out_(path) {
  if (!out_) throw std::runtime_error(path + ": cannot write the stats file");
  out_ << "frame,stamp,cpu_s,rss_kb\n";
}

void FrameStatsWriter::Add(std::uint64_t frame, double stamp) {
  char row[128];
  std::snprintf(row, sizeof(row), "%llu,%.6f,%.6f,%ld\n", static_cast<unsigned long long>(frame),
                stamp, ProcessCpuSeconds(), ResidentSetKb());
  out_ << row;
}

void FrameStatsWriter::Close() {
  out_.close();
  if (out_.fail()) throw std::runtime_error(path_ + ": writing the stats file failed");
}

}  // namespace ipm_road_mapper
