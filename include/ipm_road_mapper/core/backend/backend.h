// The back end's owned optimizer thread (docs/design.md §3): the front end submits window
// snapshots through a bounded queue and never blocks on the optimizer; the optimizer
// publishes immutable results that the front end takes when it is ready. Started in the
// constructor, stopped in Stop()/the destructor by flag + notify + join; never detached,
// never sleep-polling. In synchronous mode (offline, deterministic) Submit solves in the
// caller's thread instead.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "ipm_road_mapper/core/backend/backend_options.h"
#include "ipm_road_mapper/core/backend/window_problem.h"

namespace ipm_road_mapper {

// Counters of the optimizer, read by diagnostics and summaries.
struct BackendStats {
  std::uint64_t submitted = 0;
  std::uint64_t solved = 0;
  std::uint64_t dropped_queue_full = 0;  // oldest waiting window replaced by a newer one
  std::uint64_t unusable = 0;            // solver failure or trust bound
  std::vector<double> solve_times_s;     // one per solve, the most recent (timing_series.h)
};

class Backend {
 public:
  explicit Backend(BackendOptions options);
  ~Backend();
  Backend(const Backend&) = delete;
  Backend& operator=(const Backend&) = delete;

  // Hands a window over. Never blocks on a solve: with a full queue the oldest waiting
  // window is dropped (its frames are in the newer window anyway).
  void Submit(WindowSnapshot snapshot);

  // All results published since the last call, oldest first.
  std::vector<std::shared_ptr<const WindowResult>> TakeResults();

  // Blocks until every submitted window is solved (end of an offline run).
  void WaitIdle();
  // The same for at most timeout_s; true when idle.
  bool WaitIdleFor(double timeout_s);

  // Stops the thread (flag + notify + join); waiting windows are discarded. Idempotent.
  void Stop();

  BackendStats stats() const;

 private:
  void Run();
  void Publish(WindowResult result);

  const BackendOptions options_;
  mutable std::mutex mutex_;
  std::condition_variable work_ready_;
  std::condition_variable idle_;
  std::deque<WindowSnapshot> queue_;
  std::vector<std::shared_ptr<const WindowResult>> results_;
  BackendStats stats_;
  bool stop_ = false;
  bool busy_ = false;
  std::thread thread_;
};

}  // namespace ipm_road_mapper
