// SigintHook: the first SIGINT only wakes the hooks; the previous handler runs once every
// notified hook is done (or at once on a second SIGINT), and the handler is restored after
// the last hook.
#include <gtest/gtest.h>
#include <poll.h>
#include <signal.h>

#include <atomic>

#include "ipm_road_mapper/ros/sigint_hook.h"

namespace ipm_road_mapper {
namespace {

std::atomic<int> g_previous_calls{0};
void PreviousHandler(int) { ++g_previous_calls; }

bool Readable(int fd) {
  pollfd p{fd, POLLIN, 0};
  return ::poll(&p, 1, 0) == 1 && (p.revents & POLLIN);
}

// Runs in one process: the hook's signal state is process-wide and one-shot.
TEST(SigintHook, WaitsForEveryHookThenPassesTheSignalOn) {
  ::signal(SIGINT, PreviousHandler);
  {
    SigintHook idle;  // never signalled while alone: restores the handler
  }
  struct sigaction current {};
  ::sigaction(SIGINT, nullptr, &current);
  EXPECT_EQ(current.sa_handler, PreviousHandler);

  SigintHook a, b;
  a.Done();  // before SIGINT: a no-op, a still counts
  EXPECT_FALSE(Readable(a.fd()));
  ::raise(SIGINT);
  EXPECT_TRUE(Readable(a.fd()));
  EXPECT_TRUE(Readable(b.fd()));
  EXPECT_EQ(g_previous_calls.load(), 0);  // held until both are done
  a.Done();
  EXPECT_EQ(g_previous_calls.load(), 0);
  b.Done();
  EXPECT_EQ(g_previous_calls.load(), 1);
  b.Done();         // idempotent
  ::raise(SIGINT);  // later ones go on at once (forwarded once: the shutdown is requested)
  EXPECT_EQ(g_previous_calls.load(), 1);
}

}  // namespace
}  // namespace ipm_road_mapper
