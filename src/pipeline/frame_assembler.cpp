#include "ipm_road_mapper/pipeline/frame_assembler.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <sstream>
#include <utility>

namespace ipm_road_mapper {
namespace {

// "12.345 s" with millisecond resolution, for skip reasons.
std::string FormatStamp(double stamp) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(3);
  s << stamp << " s";
  return s.str();
}

}  // namespace

FrameAssembler::FrameAssembler(const OdometryOptions& odometry,
                               const FrameAssemblerOptions& options)
    : options_(options),
      poses_(odometry.stamp_tolerance_s, odometry.max_gap_s,
             static_cast<std::size_t>(std::max(odometry.buffer_size, 2))),
      odometry_capacity_(static_cast<std::size_t>(std::max(odometry.buffer_size, 2))) {
  if (options_.max_pending_frames == 0) options_.max_pending_frames = 1;
}

bool FrameAssembler::AddOdometry(const StampedPose& pose) {
  ++counters_.odometry_received;
  if (!std::isfinite(pose.stamp) || !IsValidTransform(pose.T_map_base)) {
    ++counters_.bad_odometry;
    return false;
  }
  if (have_odometry_stamp_ && pose.stamp <= newest_odometry_stamp_) {
    const double late_s = newest_odometry_stamp_ - pose.stamp;
    if (late_s <= ReorderWindow() && InsertLateOdometry(pose)) {
      ++counters_.odometry_reordered;
      ++counters_.odometry_used;
      return true;
    }
    if (late_s <= std::max(options_.time_jump_epsilon_s, ReorderWindow())) {
      ++counters_.odometry_out_of_order;
      return false;
    }
    HandleTimeJump("odometry went back from " + FormatStamp(newest_odometry_stamp_) + " to " +
                   FormatStamp(pose.stamp));
  }
  have_odometry_stamp_ = true;
  newest_odometry_stamp_ = pose.stamp;
  // Cannot fail: the pose is valid and its stamp is after every buffered one.
  poses_.Add(pose);
  odometry_.push_back(pose);
  if (odometry_.size() > odometry_capacity_) odometry_.pop_front();
  ++counters_.odometry_used;
  return true;
}

double FrameAssembler::ReorderWindow() const {
  // The mean spacing of the newest few poses: the stream's current rate, robust to a gap
  // long ago.
  constexpr std::size_t kPeriodSamples = 10;
  if (odometry_.size() < 2 || !(options_.reorder_periods > 0.0)) return 0.0;
  const std::size_t n = std::min(odometry_.size(), kPeriodSamples);
  const double span_s = odometry_.back().stamp - odometry_[odometry_.size() - n].stamp;
  return options_.reorder_periods * span_s / static_cast<double>(n - 1);
}

bool FrameAssembler::InsertLateOdometry(const StampedPose& pose) {
  const auto at = std::lower_bound(
      odometry_.begin(), odometry_.end(), pose.stamp,
      [](const StampedPose& buffered, double stamp) { return buffered.stamp < stamp; });
  // Two stamps this close are one message (seen twice, or re-stamped by rounding).
  constexpr double kDuplicateStampS = 1e-6;
  if (at == odometry_.begin() || at == odometry_.end() ||
      at->stamp - pose.stamp < kDuplicateStampS ||
      pose.stamp - std::prev(at)->stamp < kDuplicateStampS) {
    return false;
  }
  odometry_.insert(at, pose);
  if (odometry_.size() > odometry_capacity_) odometry_.pop_front();
  poses_.Clear();
  for (const StampedPose& buffered : odometry_) poses_.Add(buffered);
  return true;
}

void FrameAssembler::AddFrame(double stamp, cv::Mat mask, const CameraIntrinsics& camera) {
  ++counters_.frames_received;
  if (!std::isfinite(stamp)) {
    Skip("invalid_stamp", "frame stamp is not finite");
    return;
  }
  if (have_frame_stamp_ && stamp <= newest_frame_stamp_) {
    if (newest_frame_stamp_ - stamp <= options_.time_jump_epsilon_s) {
      Skip("out_of_order_frame",
           "frame at " + FormatStamp(stamp) + " is not after " + FormatStamp(newest_frame_stamp_));
      return;
    }
    HandleTimeJump("frames went back from " + FormatStamp(newest_frame_stamp_) + " to " +
                   FormatStamp(stamp));
  }
  have_frame_stamp_ = true;
  newest_frame_stamp_ = stamp;

  FrameInput frame;
  frame.stamp = stamp;
  frame.mask = std::move(mask);
  frame.camera = camera;
  pending_.push_back(std::move(frame));
  while (pending_.size() > options_.max_pending_frames) {
    const double dropped = pending_.front().stamp;
    pending_.pop_front();
    if (poses_.empty()) {
      Skip("no_odometry", "frame at " + FormatStamp(dropped) + ": no odometry received");
    } else {
      Skip("queue_overflow", "frame at " + FormatStamp(dropped) +
                                 " still waiting for odometry (newest " +
                                 FormatStamp(newest_odometry_stamp_) + ") when the queue of " +
                                 std::to_string(options_.max_pending_frames) + " was full");
    }
  }
}

std::vector<FrameInput> FrameAssembler::PopReady(std::vector<std::string>* skipped_reasons) {
  std::vector<FrameInput> ready;
  // Odometry at or after the frame's stamp decides the frame for good: interpolated, a gap,
  // or before the first pose. Frames are sorted, so the ready ones are a prefix.
  while (!pending_.empty() && !poses_.empty() && newest_odometry_stamp_ >= pending_.front().stamp) {
    ResolveFront(&ready);
  }
  TakeSkipped(skipped_reasons);
  return ready;
}

std::vector<FrameInput> FrameAssembler::Flush(std::vector<std::string>* skipped_reasons) {
  std::vector<FrameInput> ready;
  while (!pending_.empty()) ResolveFront(&ready);
  TakeSkipped(skipped_reasons);
  return ready;
}

void FrameAssembler::Reset() {
  for (const FrameInput& frame : pending_) {
    Skip("reset", "frame at " + FormatStamp(frame.stamp) + " dropped by a reset");
  }
  pending_.clear();
  poses_.Clear();
  odometry_.clear();
  have_odometry_stamp_ = have_frame_stamp_ = false;
}

void FrameAssembler::HandleTimeJump(const std::string& detail) {
  ++counters_.time_jumps;
  for (const FrameInput& frame : pending_) {
    Skip("time_jump", "frame at " + FormatStamp(frame.stamp) + " dropped: " + detail);
  }
  pending_.clear();
  poses_.Clear();
  odometry_.clear();
  // Both streams restart: the other stream's next (older) stamp is not a second jump.
  have_odometry_stamp_ = have_frame_stamp_ = false;
}

void FrameAssembler::Skip(const std::string& key, const std::string& detail) {
  ++counters_.frames_skipped[key];
  skipped_.push_back(key + ": " + detail);
}

void FrameAssembler::ResolveFront(std::vector<FrameInput>* ready) {
  FrameInput frame = std::move(pending_.front());
  pending_.pop_front();
  Eigen::Isometry3d T_map_base = Eigen::Isometry3d::Identity();
  const PoseLookupStatus status = poses_.Lookup(frame.stamp, &T_map_base);
  if (status != PoseLookupStatus::kOk) {
    std::ostringstream detail;
    detail << "frame at " << FormatStamp(frame.stamp);
    if (!poses_.empty()) {
      detail << ", newest odometry at " << FormatStamp(poses_.newest().stamp);
    }
    Skip(ToString(status), detail.str());
    return;
  }
  frame.T_map_base_odom = T_map_base;
  ++counters_.frames_ready;
  ready->push_back(std::move(frame));
}

void FrameAssembler::TakeSkipped(std::vector<std::string>* out) {
  if (out) {
    out->insert(out->end(), std::make_move_iterator(skipped_.begin()),
                std::make_move_iterator(skipped_.end()));
  }
  skipped_.clear();
}

}  // namespace ipm_road_mapper
