#include "ipm_road_mapper/ros/bag_mapping.h"

#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "ipm_road_mapper/ros/bag_camera_info.h"
#include "ipm_road_mapper/ros/bag_prefetcher.h"
#include "ipm_road_mapper/ros/msg_conversion.h"

namespace ipm_road_mapper {
namespace {

// Hands a paired mask to the session, or counts why it cannot be a frame (a bad encoding
// first, then a missing or bad camera_info).
void AddMask(const PairedMask& paired, MappingSession* session, SessionUpdate* update) {
  cv::Mat mask;
  const std::string error = ImageToMask(*paired.mask, &mask);
  if (!error.empty()) {
    session->CountSkipped("bad_mask_encoding: " + error, update);
  } else if (!paired.error.empty()) {
    session->CountSkipped(paired.error, update);
  } else {
    session->AddFrame(ToSeconds(paired.mask->header.stamp), std::move(mask), paired.camera, update);
  }
}

// Odometry as the assembler takes it: an unconvertible message (null, a zero quaternion)
// becomes a NaN pose, so it is counted as bad_odometry like any other invalid pose.
StampedPose ToPose(const nav_msgs::Odometry::ConstPtr& odometry) {
  StampedPose pose;
  if (!odometry || !OdometryToStampedPose(*odometry, &pose).empty()) {
    pose.T_map_base.matrix().setConstant(std::numeric_limits<double>::quiet_NaN());
  }
  return pose;
}

// The session calls of one MapBag run and what they report (see the header).
class BagMapping {
 public:
  BagMapping(MappingSession* session, const BagMappingCallbacks& callbacks)
      : session_(session), callbacks_(callbacks) {}

  void AddOdometry(const nav_msgs::Odometry::ConstPtr& odometry) {
    session_->AddOdometry(ToPose(odometry), &update_);
    Reported();
  }

  // Hands the paired masks to the session, in order, and empties *paired.
  void AddPaired(std::vector<PairedMask>* paired) {
    for (const PairedMask& frame : *paired) {
      AddMask(frame, session_, &update_);
      FrameDone(ToSeconds(frame.mask->header.stamp));
    }
    paired->clear();
  }

  // A message of the mapper's topics that could not be read from the bag (a corrupt chunk);
  // a mask is a frame lost and counted as such.
  void AddUnreadable(const BagPrefetcher::Item& item) {
    const bool is_mask = item.kind == BagPrefetcher::Kind::kMask;
    loss_.Lost(item.bag_time_s, is_mask, item.read_error);
    if (!is_mask) return;
    session_->CountSkipped("unreadable_chunk: " + item.read_error, &update_);
    FrameDone(std::numeric_limits<double>::quiet_NaN());
  }

  // A message that was read: a span of unreadable ones ends.
  void MessageRead() { loss_.Read(); }

  // A mask message that did not deserialize.
  void AddBadMask() {
    session_->CountSkipped("bad_mask_message: not a sensor_msgs/Image", &update_);
    FrameDone(std::numeric_limits<double>::quiet_NaN());
  }

  void Finish() {
    session_->Finish(&update_);
    Reported();
  }

  std::size_t frames_read() const { return frames_read_; }
  const BagReadLoss& lost() const { return loss_.loss(); }

 private:
  void FrameDone(double stamp) {
    if (callbacks_.frame_done) callbacks_.frame_done(frames_read_, stamp);
    ++frames_read_;
    Reported();
  }

  // Reports the first frame used, once, and clears the update.
  void Reported() {
    if (!first_frame_reported_ && !update_.used.empty()) {
      first_frame_reported_ = true;
      if (callbacks_.first_frame_mapped) callbacks_.first_frame_mapped();
    }
    update_.used.clear();
    update_.skipped.clear();
  }

  MappingSession* session_;
  const BagMappingCallbacks& callbacks_;
  SessionUpdate update_;
  BagReadLossTracker loss_;
  std::size_t frames_read_ = 0;
  bool first_frame_reported_ = false;
};

}  // namespace

BagMappingResult MapBag(const rosbag::Bag& bag, const RosOptions& topics, MappingSession* session,
                        const BagMappingCallbacks& callbacks) {
  bool read_failed = false;  // then the prefetcher reads from a freshly opened bag
  CameraInfoPairing pairing(CameraInfoTable(CameraInfoTable::ToleranceFromFirstMessages(
                                bag, topics.camera_info_topic, 20, &read_failed)),
                            topics.sync == "exact");
  BagMapping mapping(session, callbacks);
  std::vector<PairedMask> paired;
  {
    BagPrefetcher prefetcher(bag, {topics.mask_topic, topics.odom_topic, topics.camera_info_topic},
                             16, read_failed);
    BagPrefetcher::Item message;
    while (prefetcher.Next(&message)) {
      if (!message.read_error.empty()) {
        mapping.AddUnreadable(message);
        continue;
      }
      mapping.MessageRead();
      switch (message.kind) {
        case BagPrefetcher::Kind::kOdometry:
          mapping.AddOdometry(message.odometry);
          break;
        case BagPrefetcher::Kind::kCameraInfo:
          // One that does not deserialize is left out (its mask reports no_camera_info).
          if (message.camera_info) pairing.AddCameraInfo(*message.camera_info, &paired);
          break;
        case BagPrefetcher::Kind::kMask:
          if (message.mask) {
            pairing.AddMask(message.mask, &paired);
          } else {
            mapping.AddBadMask();
          }
          break;
      }
      mapping.AddPaired(&paired);
    }
  }
  pairing.Flush(&paired);
  mapping.AddPaired(&paired);
  mapping.Finish();
  return {mapping.frames_read(), mapping.lost()};
}

}  // namespace ipm_road_mapper
