// A progress bar for the offline tools on stderr: items done, items/s and ETA. On a
// terminal it redraws one line in place (\r) at most every 0.2 s; otherwise (a log file, a
// CI job) it prints a new line every 10% so logs stay short.
#pragma once

#include <chrono>
#include <cstdio>
#include <string>

namespace ipm_road_mapper {

// Throttled progress display of `total` items (see the file comment).
class ProgressMeter {
 public:
  // `unit` names the items ("frames"). `interactive`: redraw in place (true when `out` is a
  // TTY; the constructor that takes no flag checks it).
  ProgressMeter(std::size_t total, std::string unit, std::FILE* out, bool interactive);
  ProgressMeter(std::size_t total, std::string unit, std::FILE* out = stderr);

  // Sets the number of items done and redraws if the throttle allows.
  void Update(std::size_t done);

  // Draws the final state and ends the line (idempotent).
  void Finish();

  // The text of one progress line, e.g. "[#####-----]  50/100 frames  12.5 frames/s  ETA 0:04"
  // (exposed for tests).
  static std::string Format(std::size_t done, std::size_t total, const std::string& unit,
                            double elapsed_s);

 private:
  using Clock = std::chrono::steady_clock;
  void Draw(bool final_line);
  double ElapsedSeconds() const;

  std::size_t total_;
  std::string unit_;
  std::FILE* out_;
  bool interactive_;
  std::size_t done_ = 0;
  int last_decile_ = -1;
  Clock::time_point start_;
  Clock::time_point last_draw_;
  bool finished_ = false;
};

}  // namespace ipm_road_mapper
