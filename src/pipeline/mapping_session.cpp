#include "ipm_road_mapper/pipeline/mapping_session.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace ipm_road_mapper {
MappingSession::MappingSession(MapperOptions options, ClassTable classes, double odometry_wait_s)
    : options_(std::move(options)),
      classes_(std::move(classes)),
      odometry_wait_s_(odometry_wait_s),
      assembler_(options_.odometry) {}

void MappingSession::Start(const Eigen::Isometry3d& T_base_cam_initial) {
  if (mapper_) return;
  mapper_ = std::make_unique<Mapper>(options_, classes_, T_base_cam_initial);
  // The frames seen before the extrinsic was known belong in the Mapper's counters too.
  for (const auto& [reason, count] : skipped_before_start_) {
    for (std::uint64_t i = 0; i < count; ++i) mapper_->CountSkipped(reason);
  }
}

void MappingSession::AddOdometry(const StampedPose& pose, SessionUpdate* update) {
  if (assembler_.AddOdometry(pose)) newest_odometry_stamp_ = pose.stamp;
  std::vector<std::string> skipped;
  std::vector<FrameInput> ready = assembler_.PopReady(&skipped);
  Process(std::move(ready), std::move(skipped), update);
}

void MappingSession::AddFrame(double stamp, cv::Mat mask, const CameraIntrinsics& camera,
                              SessionUpdate* update) {
  if (!mapper_) {
    CountSkipped("no_extrinsic: the rough extrinsic is not known yet", update);
    return;
  }
  if (newest_frame_stamp_ && stamp < *newest_frame_stamp_) oldest_waiting_stamp_.reset();
  newest_frame_stamp_ = stamp;
  assembler_.AddFrame(stamp, std::move(mask), camera);
  std::vector<std::string> skipped;
  std::vector<FrameInput> ready = assembler_.PopReady(&skipped);
  if (assembler_.pending_frames() == 0) {
    oldest_waiting_stamp_.reset();
  } else if (!oldest_waiting_stamp_) {
    oldest_waiting_stamp_ = stamp;
  }
  if (OdometryOverdue()) {
    std::vector<FrameInput> flushed = assembler_.Flush(&skipped);
    ready.insert(ready.end(), flushed.begin(), flushed.end());
    oldest_waiting_stamp_.reset();
  }
  Process(std::move(ready), std::move(skipped), update);
}

bool MappingSession::OdometryOverdue() const {
  if (odometry_wait_s_ <= 0.0 || assembler_.pending_frames() == 0 || !newest_frame_stamp_) {
    return false;
  }
  double reference = -INFINITY;
  if (newest_odometry_stamp_) reference = *newest_odometry_stamp_;
  if (oldest_waiting_stamp_) reference = std::max(reference, *oldest_waiting_stamp_);
  return *newest_frame_stamp_ - reference > odometry_wait_s_;
}

void MappingSession::CountSkipped(const std::string& reason, SessionUpdate* update) {
  if (mapper_) {
    mapper_->CountSkipped(reason);
  } else {
    ++skipped_before_start_[reason.substr(0, reason.find(':'))];
  }
  if (update) update->skipped.push_back(reason);
}

void MappingSession::Process(std::vector<FrameInput> frames, std::vector<std::string> skipped,
                             SessionUpdate* update) {
  for (const std::string& reason : skipped) CountSkipped(reason, update);
  for (FrameInput& frame : frames) {
    if (!mapper_) {  // not reachable (frames are queued only after Start), but never crash
      CountSkipped("no_extrinsic: the rough extrinsic is not known yet", update);
      continue;
    }
    std::string reason;
    if (mapper_->ProcessFrame(frame, &reason) == FrameStatus::kUsed) {
      if (update) update->used.push_back(std::move(frame));
    } else if (update) {
      update->skipped.push_back(reason);
    }
  }
}

void MappingSession::Finish(SessionUpdate* update, double time_budget_s) {
  std::vector<std::string> skipped;
  std::vector<FrameInput> ready = assembler_.Flush(&skipped);
  if (!mapper_) {
    for (const std::string& reason : skipped) CountSkipped(reason, update);
    return;
  }
  Process(std::move(ready), std::move(skipped), update);
  mapper_->Finish(time_budget_s);
}

void MappingSession::Reset() {
  assembler_.Reset();
  if (mapper_) mapper_->Reset();
  newest_odometry_stamp_.reset();
  newest_frame_stamp_.reset();
  oldest_waiting_stamp_.reset();
}

}  // namespace ipm_road_mapper
