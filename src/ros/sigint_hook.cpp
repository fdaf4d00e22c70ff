#include "ipm_road_mapper/ros/sigint_hook.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cstring>
#include <mutex>
#include <stdexcept>
#include <string>

namespace ipm_road_mapper {
namespace {

// Process-wide by nature: there is one SIGINT disposition per process.
constexpr std::size_t kSlots = 32;
std::array<std::atomic<int>, kSlots> g_slots{};  // a hook's write fd + 1; 0 = free
std::atomic<int> g_pending{0};                   // notified hooks not done yet
std::atomic<bool> g_signalled{false};            // the first SIGINT arrived
std::atomic<bool> g_forwarded{false};            // passed on to the previous handler
struct sigaction g_previous {};                  // written under g_install_mutex before install
std::mutex g_install_mutex;                      // registration (never taken in the handler)
int g_registered = 0;                            // under g_install_mutex

void Forward(int sig) {
  if (g_forwarded.exchange(true)) return;
  if (g_previous.sa_flags & SA_SIGINFO) {
    if (g_previous.sa_sigaction) g_previous.sa_sigaction(sig, nullptr, nullptr);
  } else if (g_previous.sa_handler == SIG_DFL) {
    ::signal(sig, SIG_DFL);
    ::raise(sig);
  } else if (g_previous.sa_handler != SIG_IGN && g_previous.sa_handler != nullptr) {
    g_previous.sa_handler(sig);
  }
}

void OnSigint(int sig) {
  if (g_signalled.exchange(true)) {
    Forward(sig);  // a second Ctrl-C: no more waiting
    return;
  }
  // One count for this handler, so that no hook done early forwards before every hook was
  // notified; one per hook notified.
  g_pending.store(1);
  for (auto& slot : g_slots) {
    const int w = slot.load() - 1;
    if (w < 0) continue;
    g_pending.fetch_add(1);
    const char byte = 1;
    if (::write(w, &byte, 1) != 1) g_pending.fetch_sub(1);
  }
  if (g_pending.fetch_sub(1) == 1) Forward(sig);
}

}  // namespace

SigintHook::SigintHook() {
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC | O_NONBLOCK) != 0) {
    throw std::runtime_error(std::string("SigintHook: pipe: ") + std::strerror(errno));
  }
  read_fd_ = fds[0];
  write_fd_ = fds[1];
  std::lock_guard<std::mutex> lock(g_install_mutex);
  for (std::size_t i = 0; i < kSlots && slot_ < 0; ++i) {
    int expected = 0;
    if (g_slots[i].compare_exchange_strong(expected, write_fd_ + 1)) slot_ = static_cast<int>(i);
  }
  if (slot_ < 0) {
    ::close(read_fd_);
    ::close(write_fd_);
    throw std::runtime_error("SigintHook: every slot is taken");
  }
  if (g_registered++ == 0) {
    struct sigaction action {};
    action.sa_handler = OnSigint;
    sigemptyset(&action.sa_mask);
    action.sa_flags = SA_RESTART;
    ::sigaction(SIGINT, &action, &g_previous);
  }
}

SigintHook::~SigintHook() {
  {
    std::lock_guard<std::mutex> lock(g_install_mutex);
    g_slots[static_cast<std::size_t>(slot_)].store(0);
    if (--g_registered == 0 && !g_signalled.load()) ::sigaction(SIGINT, &g_previous, nullptr);
  }
  if (g_signalled.load() && !done_) {
    // A handler running right now may still write to this pipe: give it a moment.
    pollfd p{read_fd_, POLLIN, 0};
    ::poll(&p, 1, 100);
  }
  Done();
  ::close(read_fd_);
  ::close(write_fd_);
}

void SigintHook::Done() {
  if (done_) return;
  // Only a hook that was notified counts (its pipe holds the byte).
  char byte = 0;
  if (::read(read_fd_, &byte, 1) != 1) return;
  done_ = true;
  if (g_pending.fetch_sub(1) == 1) Forward(SIGINT);
}

}  // namespace ipm_road_mapper
