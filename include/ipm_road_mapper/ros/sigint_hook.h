// Lets a nodelet do its last work (the shutdown save) and log it while roscpp still runs.
// On SIGINT roscpp's handler requests ros::shutdown(), which shuts rosconsole down first:
// a nodelet destroyed afterwards (manager or mapper_node exiting) can no longer log. A
// SigintHook puts a handler in front of the process's SIGINT handler (installed with the
// first hook, the previous one restored with the last): on the first SIGINT it only
// makes every hook's fd() readable; once every notified hook called Done(), the signal is
// passed on to the previous handler (roscpp: ros::requestShutdown()). A second SIGINT is
// passed on at once. The handler does nothing but async-signal-safe writes and loads.
#pragma once

namespace ipm_road_mapper {

class SigintHook {
 public:
  // Registers this hook (installs the handler with the first one). Throws
  // std::runtime_error when no pipe can be made or every slot is taken.
  SigintHook();
  // Done() if notified and not done yet; unregisters (the last restores the handler).
  ~SigintHook();
  SigintHook(const SigintHook&) = delete;
  SigintHook& operator=(const SigintHook&) = delete;

  // Readable (poll POLLIN) once SIGINT arrived; poll it, do not read it (Done() does).
  int fd() const { return read_fd_; }

  // When notified: this hook's work is done, and the last notified hook to call it passes
  // SIGINT on. A no-op before SIGINT; idempotent.
  void Done();

 private:
  int slot_ = -1;
  int read_fd_ = -1, write_fd_ = -1;
  bool done_ = false;
};

}  // namespace ipm_road_mapper
