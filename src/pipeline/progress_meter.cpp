#include "ipm_road_mapper/pipeline/progress_meter.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace ipm_road_mapper {
namespace {

constexpr double kRedrawPeriod_s = 0.2;
constexpr int kBarWidth = 24;

std::string FormatDuration(double seconds) {
  const long total = std::lround(std::max(0.0, seconds));
  std::ostringstream s;
  if (total >= 3600) s << total / 3600 << ":" << (total / 60 % 60 < 10 ? "0" : "");
  s << total / 60 % 60 << ":" << (total % 60 < 10 ? "0" : "") << total % 60;
  return s.str();
}

}  // namespace

ProgressMeter::ProgressMeter(std::size_t total, std::string unit, std::FILE* out, bool interactive)
    : total_(total),
      unit_(std::move(unit)),
      out_(out),
      interactive_(interactive),
      start_(Clock::now()),
      last_draw_(start_) {}

ProgressMeter::ProgressMeter(std::size_t total, std::string unit, std::FILE* out)
    : ProgressMeter(total, std::move(unit), out, isatty(fileno(out)) != 0) {}

std::string ProgressMeter::Format(std::size_t done, std::size_t total, const std::string& unit,
                                  double elapsed_s) {
  const double fraction = total > 0 ? std::min(1.0, static_cast<double>(done) / total) : 1.0;
  const int filled = static_cast<int>(std::lround(fraction * kBarWidth));
  const double rate = elapsed_s > 0.0 ? done / elapsed_s : 0.0;
  std::ostringstream s;
  s << "[" << std::string(filled, '#') << std::string(kBarWidth - filled, '-') << "] " << done
    << "/" << total << " " << unit << " " << std::lround(100.0 * fraction) << "%  ";
  s.setf(std::ios::fixed);
  s.precision(1);
  s << rate << " " << unit << "/s  ";
  if (done >= total) {
    s << "took " << FormatDuration(elapsed_s);
  } else if (rate > 0.0) {
    s << "ETA " << FormatDuration((total - done) / rate);
  } else {
    s << "ETA ?";
  }
  return s.str();
}

void ProgressMeter::Update(std::size_t done) {
  done_ = done;
  if (finished_) return;
  if (interactive_) {
    const Clock::time_point now = Clock::now();
    if (std::chrono::duration<double>(now - last_draw_).count() < kRedrawPeriod_s) return;
    last_draw_ = now;
    Draw(false);
    return;
  }
  const int decile = total_ > 0 ? static_cast<int>(10 * std::min(done, total_) / total_) : 10;
  if (decile > last_decile_ && decile < 10) {
    last_decile_ = decile;
    Draw(false);
  }
}

void ProgressMeter::Finish() {
  if (finished_) return;
  Draw(true);
  finished_ = true;
}

void ProgressMeter::Draw(bool final_line) {
  const std::string line = Format(done_, total_, unit_, ElapsedSeconds());
  if (interactive_) {
    // Pad so a shorter line fully overwrites the previous one.
    std::fprintf(out_, "\r%-100s%s", line.c_str(), final_line ? "\n" : "");
  } else {
    std::fprintf(out_, "%s\n", line.c_str());
  }
  std::fflush(out_);
}

double ProgressMeter::ElapsedSeconds() const {
  return std::chrono::duration<double>(Clock::now() - start_).count();
}

}  // namespace ipm_road_mapper
