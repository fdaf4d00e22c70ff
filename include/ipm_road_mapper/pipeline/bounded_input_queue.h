// A bounded FIFO between producers that must never block (the nodelet's data callbacks) and
// one consumer thread (the mapping thread). When full, Push drops the oldest item and hands
// it back, so the caller can count the drop by its kind. The consumer waits on a condition
// variable (never sleep-polls) until an item, a Wake() or its deadline. No ROS header.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <mutex>
#include <optional>
#include <utility>

namespace ipm_road_mapper {

template <typename T>
class BoundedInputQueue {
 public:
  using Clock = std::chrono::steady_clock;

  // Holds at most `capacity` (>= 1) items.
  explicit BoundedInputQueue(std::size_t capacity) : capacity_(capacity > 0 ? capacity : 1) {}

  // Appends `item`; returns the oldest item when it had to be dropped to make room. Holds
  // the mutex only for the deque operation. Ignored (returns nothing) after Close().
  std::optional<T> Push(T item) {
    std::optional<T> dropped;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (closed_) return std::nullopt;
      if (items_.size() >= capacity_) {
        dropped = std::move(items_.front());
        items_.pop_front();
      }
      items_.push_back(std::move(item));
    }
    ready_.notify_one();
    return dropped;
  }

  // Takes the oldest item into *item (true), or returns false when `deadline` passed, when
  // Wake() was called, or when the queue is closed and empty.
  bool PopUntil(Clock::time_point deadline, T* item) {
    std::unique_lock<std::mutex> lock(mutex_);
    ready_.wait_until(lock, deadline, [this] { return !items_.empty() || woken_ || closed_; });
    woken_ = false;
    if (items_.empty()) return false;
    *item = std::move(items_.front());
    items_.pop_front();
    return true;
  }

  // Makes the waiting (or the next) PopUntil return false at once, e.g. for a command.
  void Wake() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      woken_ = true;
    }
    ready_.notify_one();
  }

  // No more pushes; the consumer drains what is left, then PopUntil returns false at once.
  void Close() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      closed_ = true;
    }
    ready_.notify_all();
  }

  // Items waiting now.
  std::size_t size() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return items_.size();
  }
  std::size_t capacity() const { return capacity_; }

 private:
  const std::size_t capacity_;
  mutable std::mutex mutex_;  // items_, woken_, closed_
  std::condition_variable ready_;
  std::deque<T> items_;
  bool woken_ = false;
  bool closed_ = false;
};

}  // namespace ipm_road_mapper
