// What a run costs the process, for the offline runner's statistics (map_from_bag's
// `startup_s` and its --stats-out CSV): CPU time of all threads, the resident set size, and
// the wall time since the process started. Linux (/proc); no ROS.
#pragma once

#include <cstdint>
#include <fstream>
#include <string>

namespace ipm_road_mapper {

// CPU time (user + system) of the whole process, all threads, in s
// (clock_gettime(CLOCK_PROCESS_CPUTIME_ID)).
double ProcessCpuSeconds();

// The current resident set size in kB (/proc/self/statm: resident pages * page size); -1
// when it cannot be read.
long ResidentSetKb();

// Wall time since the process was started (exec), in s: the start time of /proc/self/stat
// (clock ticks since boot, 10 ms resolution) against CLOCK_BOOTTIME, so dynamic loading and
// static initialization count. Falls back to the time since this library was loaded when
// /proc cannot be read.
double SecondsSinceProcessStart();

// The per-frame CSV of map_from_bag --stats-out: header `frame,stamp,cpu_s,rss_kb`, then one
// row per frame with the process's CPU time and resident set size right after it was
// processed (docs/map_from_bag.md).
class FrameStatsWriter {
 public:
  // Creates (truncates) `path` and writes the header; throws std::runtime_error when it
  // cannot be opened.
  explicit FrameStatsWriter(const std::string& path);

  // Appends the row of one frame: its 0-based index and stamp (s), with ProcessCpuSeconds()
  // and ResidentSetKb() taken now.
  void Add(std::uint64_t frame, double stamp);

  // Flushes and closes the file; throws std::runtime_error when a write failed.
  void Close();

  const std::string& path() const { return path_; }

 private:
  std::string path_;
  std::ofstream out_;
};

}  // namespace ipm_road_mapper
