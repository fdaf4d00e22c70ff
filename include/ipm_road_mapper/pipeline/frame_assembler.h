// Turns the time-ordered streams of odometry poses and (stamp, mask, camera) frames into
// FrameInputs whose odometry pose is interpolated at the mask stamp (docs/design.md §2 "Time").
// Shared by the offline runner (map_from_bag) and the nodelet, so that a map made offline
// and one made live see the same frames with the same poses. No ROS, no I/O, not
// thread-safe (the caller owns the locking).
//
// Rules:
// - A frame waits in a bounded queue until odometry at or after its stamp has arrived, so
//   its pose is interpolated between two bracketing poses rather than taken from the
//   nearest one. Flush() (end of input) resolves the waiting frames with the tolerance rule
//   of PoseBuffer (nearest pose within OdometryOptions::stamp_tolerance_s).
// - A frame that cannot get a pose is skipped with a reason, never guessed. Reason strings
//   are "<key>: <detail>", keys: no_odometry, before_first_odometry, after_last_odometry,
//   odometry_gap, invalid_stamp, out_of_order_frame, queue_overflow, time_jump (the part
//   before ':' is the counter key, as Mapper::CountSkipped expects).
// - Odometry a little out of order (older than the newest pose by at most
//   reorder_periods odometry periods, the period measured from the buffered poses: a
//   transport that swaps two messages) is inserted in stamp order and counted as
//   odometry_reordered; a frame already returned keeps the pose it got. A duplicate stamp,
//   or one older than the buffer, is out of order (ignored).
// - A time jump backwards (an odometry or a mask stamp older than the newest one of its own
//   stream by more than time_jump_epsilon_s and, for odometry, the reorder window: a bag
//   loop, a restarted player) clears the waiting frames (skipped as time_jump) and the pose
//   buffer and is counted. What happens to the map is the caller's decision.
// - When the queue is full, the oldest frame is dropped as queue_overflow (as no_odometry
//   when no odometry has arrived at all, which is the more useful diagnosis).
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <map>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "ipm_road_mapper/core/geometry/pinhole_camera.h"
#include "ipm_road_mapper/core/geometry/rigid_transform.h"
#include "ipm_road_mapper/core/mapper/mapper.h"
#include "ipm_road_mapper/core/mapper/mapper_options.h"

namespace ipm_road_mapper {

// Tuning of the assembler beyond OdometryOptions.
struct FrameAssemblerOptions {
  std::size_t max_pending_frames = 50;  // frames waiting for odometry (5 s at 10 Hz)
  double time_jump_epsilon_s = 0.01;    // a stream going back by more than this: time jump
  double reorder_periods = 3.0;         // odometry this many periods late is reordered (0 = never)
};

// What the assembler received and refused, for summaries and diagnostics. Frames it could
// not build are also returned as reasons by PopReady/Flush so the caller can count them.
struct FrameAssemblerCounters {
  std::uint64_t odometry_received = 0;
  std::uint64_t odometry_used = 0;          // accepted into the pose buffer
  std::uint64_t bad_odometry = 0;           // non-finite stamp or pose, not a rotation
  std::uint64_t odometry_out_of_order = 0;  // duplicate or too old to insert, not a jump
  std::uint64_t odometry_reordered = 0;     // late within the reorder window: inserted
  std::uint64_t time_jumps = 0;             // backwards jumps of either stream
  std::uint64_t frames_received = 0;
  std::uint64_t frames_ready = 0;                       // returned with a pose
  std::map<std::string, std::uint64_t> frames_skipped;  // reason key -> count
};

// Pairs masks with odometry interpolated at their stamps (see the file comment).
class FrameAssembler {
 public:
  explicit FrameAssembler(const OdometryOptions& odometry,
                          const FrameAssemblerOptions& options = FrameAssemblerOptions());

  // Adds an odometry pose (T_map_base at its stamp). Returns false when the pose is not
  // used: invalid (counted as bad_odometry), or not after the newest pose and neither
  // insertable in the reorder window nor a jump (counted as odometry_out_of_order). A pose
  // older by more than the reorder window and the epsilon is a time jump: the buffers are
  // cleared and the pose starts the new stream (true).
  bool AddOdometry(const StampedPose& pose);

  // Queues a frame (the mask is shared, not copied). A frame whose stamp is not finite or
  // not after the newest queued/returned frame (within the epsilon) is skipped with a
  // reason; one older by more than the epsilon is a time jump (then it is queued).
  void AddFrame(double stamp, cv::Mat mask, const CameraIntrinsics& camera);

  // Frames whose pose is decided, in stamp order: ready ones are returned, failed ones
  // (and those dropped since the last call) are appended to *skipped_reasons (if given).
  std::vector<FrameInput> PopReady(std::vector<std::string>* skipped_reasons);

  // End of input: decides every waiting frame with the tolerance rule, as PopReady.
  std::vector<FrameInput> Flush(std::vector<std::string>* skipped_reasons);

  // Forgets all frames, poses and stream stamps (counters are kept).
  void Reset();

  std::size_t pending_frames() const { return pending_.size(); }
  const FrameAssemblerCounters& counters() const { return counters_; }

 private:
  // Drops every waiting frame and the pose buffer; counts one time jump.
  void HandleTimeJump(const std::string& detail);
  // How far back (s) a late odometry pose may be and still be inserted: reorder_periods
  // times the mean spacing of the newest buffered poses; 0 with fewer than two.
  double ReorderWindow() const;
  // Inserts a late pose into the buffer in stamp order; false for a duplicate stamp or one
  // before the oldest buffered pose.
  bool InsertLateOdometry(const StampedPose& pose);
  // Records a skipped frame with "<key>: <detail>".
  void Skip(const std::string& key, const std::string& detail);
  // Looks up the pose of the oldest waiting frame; appends it to `ready` or skips it.
  void ResolveFront(std::vector<FrameInput>* ready);
  // Moves the skipped reasons collected so far into *out.
  void TakeSkipped(std::vector<std::string>* out);

  FrameAssemblerOptions options_;
  PoseBuffer poses_;
  // The buffer's poses in stamp order (PoseBuffer only appends): rebuilt into poses_ when a
  // late pose is inserted.
  std::deque<StampedPose> odometry_;
  std::size_t odometry_capacity_ = 2;
  std::deque<FrameInput> pending_;  // sorted by stamp
  std::vector<std::string> skipped_;
  bool have_odometry_stamp_ = false;
  double newest_odometry_stamp_ = 0.0;
  bool have_frame_stamp_ = false;
  double newest_frame_stamp_ = 0.0;
  FrameAssemblerCounters counters_;
};

}  // namespace ipm_road_mapper
