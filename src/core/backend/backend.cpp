#include "ipm_road_mapper/core/backend/backend.h"

#include <algorithm>
#include <chrono>
#include <utility>

#include "ipm_road_mapper/core/mapper/timing_series.h"

namespace ipm_road_mapper {

Backend::Backend(BackendOptions options) : options_(std::move(options)) {
  if (!options_.synchronous) thread_ = std::thread(&Backend::Run, this);
}

Backend::~Backend() { Stop(); }

void Backend::Stop() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
    queue_.clear();
  }
  work_ready_.notify_all();
  idle_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void Backend::Submit(WindowSnapshot snapshot) {
  if (options_.synchronous) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      ++stats_.submitted;
    }
    Publish(SolveWindow(snapshot, options_));
    return;
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (stop_) return;
    ++stats_.submitted;
    while (static_cast<int>(queue_.size()) >= options_.queue_size) {
      queue_.pop_front();
      ++stats_.dropped_queue_full;
    }
    queue_.push_back(std::move(snapshot));
  }
  work_ready_.notify_one();
}

std::vector<std::shared_ptr<const WindowResult>> Backend::TakeResults() {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<std::shared_ptr<const WindowResult>> out;
  out.swap(results_);
  return out;
}

void Backend::WaitIdle() {
  std::unique_lock<std::mutex> lock(mutex_);
  idle_.wait(lock, [this] { return stop_ || (queue_.empty() && !busy_); });
}

bool Backend::WaitIdleFor(double timeout_s) {
  std::unique_lock<std::mutex> lock(mutex_);
  auto idle = [this] { return stop_ || (queue_.empty() && !busy_); };
  if (!(timeout_s < 1e9)) {
    idle_.wait(lock, idle);
    return true;
  }
  return idle_.wait_for(lock, std::chrono::duration<double>(std::max(0.0, timeout_s)), idle);
}

BackendStats Backend::stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return stats_;
}

void Backend::Publish(WindowResult result) {
  std::lock_guard<std::mutex> lock(mutex_);
  ++stats_.solved;
  if (!result.usable) ++stats_.unusable;
  AppendBounded(&stats_.solve_times_s, result.solve_time_s);
  results_.push_back(std::make_shared<const WindowResult>(std::move(result)));
}

void Backend::Run() {
  for (;;) {
    WindowSnapshot snapshot;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      work_ready_.wait(lock, [this] { return stop_ || !queue_.empty(); });
      if (stop_) return;
      snapshot = std::move(queue_.front());
      queue_.pop_front();
      busy_ = true;
    }
    WindowResult result = SolveWindow(snapshot, options_);
    Publish(std::move(result));
    {
      std::lock_guard<std::mutex> lock(mutex_);
      busy_ = false;
    }
    idle_.notify_all();
  }
}

}  // namespace ipm_road_mapper
