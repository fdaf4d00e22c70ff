#include "ipm_road_mapper/ros/map_saver.h"

#include <fcntl.h>
#include <poll.h>
#include <ros/console.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <utility>

namespace ipm_road_mapper {
namespace {

constexpr double kErrorLogPeriodS = 30.0;  // autosave failures are logged at most this often

double WallNow() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

}  // namespace

MapSaver::MapSaver(std::string json_path, std::optional<GeoOrigin> geo_origin, double period_s,
                   std::string node_name, LatestFn latest, SigintFn on_sigint)
    : geo_origin_(std::move(geo_origin)),
      period_s_(period_s),
      node_name_(std::move(node_name)),
      latest_(std::move(latest)),
      on_sigint_(std::move(on_sigint)),
      target_(json_path) {
  status_.path = json_path;
  status_.autosave_period_s = period_s;
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC | O_NONBLOCK) != 0) {
    throw std::runtime_error(std::string("MapSaver: pipe: ") + std::strerror(errno));
  }
  stop_read_fd_ = fds[0];
  stop_write_fd_ = fds[1];
  if (on_sigint_) sigint_ = std::make_unique<SigintHook>();
  thread_ = std::thread([this] { Run(); });
}

MapSaver::~MapSaver() {
  Stop();
  sigint_.reset();
  ::close(stop_read_fd_);
  ::close(stop_write_fd_);
}

void MapSaver::Stop() {
  if (!thread_.joinable()) return;
  const char byte = 1;
  [[maybe_unused]] const ssize_t n = ::write(stop_write_fd_, &byte, 1);
  thread_.join();
}

void MapSaver::Run() {
  using Clock = std::chrono::steady_clock;
  const auto period = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(period_s_ > 0.0 ? period_s_ : 0.0));
  Clock::time_point next = Clock::now() + period;
  while (true) {
    int timeout_ms = -1;  // no autosave: wait for stop or SIGINT only
    if (period_s_ > 0.0) {
      const double left_ms = std::chrono::duration<double, std::milli>(next - Clock::now()).count();
      timeout_ms = static_cast<int>(std::ceil(std::max(0.0, left_ms)));
    }
    pollfd fds[2] = {{stop_read_fd_, POLLIN, 0}, {sigint_ ? sigint_->fd() : -1, POLLIN, 0}};
    const int ready = ::poll(fds, 2, timeout_ms);
    if (ready < 0 && errno == EINTR) continue;
    if (fds[0].revents & POLLIN) return;
    if (fds[1].revents & POLLIN) {
      on_sigint_();  // the final save, while roscpp still logs
      sigint_->Done();
      return;
    }
    if (period_s_ > 0.0 && Clock::now() >= next) {
      Autosave();
      next = Clock::now() + period;
    }
  }
}

void MapSaver::Autosave() {
  const std::shared_ptr<const MapSnapshot> snapshot = latest_();
  if (!snapshot->map) return;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (saved_any_ && snapshot->map_version == saved_version_) return;  // unchanged
  }
  const MapSaveResult result = Save(*snapshot->FullMap(), snapshot->resets);
  if (result.ok) {
    std::lock_guard<std::mutex> lock(mutex_);
    saved_any_ = true;
    saved_version_ = snapshot->map_version;
    ROS_DEBUG("%s: autosave: %s", node_name_.c_str(), result.message.c_str());
    return;
  }
  // Throttled on the wall clock (ROS time may be a paused bag's), once per kErrorLogPeriodS.
  const auto now = std::chrono::steady_clock::now();
  if (logged_error_ && now - last_error_log_ < std::chrono::duration<double>(kErrorLogPeriodS)) {
    return;
  }
  logged_error_ = true;
  last_error_log_ = now;
  ROS_ERROR("%s: autosave to %s failed: %s (logged at most every %.0f s; see /diagnostics)",
            node_name_.c_str(), result.paths.json.c_str(), result.message.c_str(),
            kErrorLogPeriodS);
}

MapSaveResult MapSaver::Save(const VectorMap& map, std::uint64_t generation) {
  std::lock_guard<std::mutex> lock(mutex_);
  MapSaveResult result;
  const std::size_t elements = MapElementCount(map);
  result.paths = target_.Choose(generation, elements, &result.diverted);
  try {
    SaveMapFiles(map, geo_origin_, result.paths);
    target_.Saved(generation, elements);
    result.ok = true;
    result.message = std::to_string(map.markings.size()) + " markings, " +
                     std::to_string(map.lanes.size()) + " lanes to " +
                     SavedFilesText(result.paths, geo_origin_.has_value());
    if (result.diverted) {
      result.message += " (after ~reset " + std::to_string(generation) +
                        ": fewer elements than the last save, which " + target_.json_path() +
                        " keeps)";
    }
  } catch (const std::exception& e) {
    result.message = e.what();
  }
  ++status_.saves;
  if (!result.ok) ++status_.failures;
  status_.last_wall_time = WallNow();
  status_.last_ok = result.ok;
  status_.last_status = (result.ok ? "ok: " : "") + result.message;
  if (result.ok && result.diverted && generation != logged_diverted_) {
    logged_diverted_ = generation;  // once per reset
    ROS_WARN(
        "%s: the map after ~reset %lu has fewer elements than the last save: saved apart, "
        "%s",
        node_name_.c_str(), static_cast<unsigned long>(generation), result.message.c_str());
  }
  return result;
}

MapSaveStatus MapSaver::status() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return status_;
}

}  // namespace ipm_road_mapper
