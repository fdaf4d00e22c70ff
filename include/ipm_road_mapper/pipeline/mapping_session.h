// The frame pipeline both runners drive, so that a map made offline (map_from_bag) and one
// made live (the nodelet) from the same messages see the same frames with the same poses:
// odometry and masks go into the FrameAssembler, the frames it decides go through the core
// Mapper, and every frame that cannot be used is counted by reason. The Mapper is created
// when the rough extrinsic is known (Start); frames before that are counted as
// `no_extrinsic` and the counts are handed to the Mapper when it starts. No ROS header, not
// thread-safe: the nodelet calls it from its mapping thread only (MappingWorker).
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "ipm_road_mapper/core/frontend/class_table.h"
#include "ipm_road_mapper/core/mapper/mapper.h"
#include "ipm_road_mapper/core/mapper/mapper_options.h"
#include "ipm_road_mapper/pipeline/frame_assembler.h"

namespace ipm_road_mapper {

// What one call did: the frames the Mapper used (their masks are shared, not copied) and
// the skip reasons of the frames it did not use ("<key>: <detail>").
struct SessionUpdate {
  std::vector<FrameInput> used;
  std::vector<std::string> skipped;
};

// Assembler + Mapper with the live-input rules (see the file comment).
class MappingSession {
 public:
  // `odometry_wait_s` > 0: when the newest mask is that much newer than both the newest
  // odometry and the oldest waiting mask, the waiting masks are decided at once
  // (FrameAssembler::Flush) instead of waiting for the queue to overflow; 0 = never (the
  // offline runner, which sees the whole bag).
  MappingSession(MapperOptions options, ClassTable classes, double odometry_wait_s = 0.0);

  // Creates the Mapper with the rough extrinsic (idempotent: a second call does nothing).
  void Start(const Eigen::Isometry3d& T_base_cam_initial);
  bool started() const { return mapper_ != nullptr; }

  // Adds an odometry pose (a NaN pose is counted as bad_odometry by the assembler) and
  // processes the frames it completes.
  void AddOdometry(const StampedPose& pose, SessionUpdate* update);

  // Queues a frame and processes the frames that are decided. Before Start, the frame is
  // counted as `no_extrinsic`.
  void AddFrame(double stamp, cv::Mat mask, const CameraIntrinsics& camera, SessionUpdate* update);

  // Counts a frame the caller could not build (bad encoding, no camera_info, ...).
  void CountSkipped(const std::string& reason, SessionUpdate* update);

  // End of input: decides every waiting frame, then Mapper::Finish(time_budget_s) (the last
  // window solved, in at most about `time_budget_s` of wall time; infinity = no limit).
  void Finish(SessionUpdate* update,
              double time_budget_s = std::numeric_limits<double>::infinity());

  // Drops the map and every waiting frame and pose; options, extrinsic and counters stay.
  void Reset();

  // The Mapper (nullptr before Start).
  Mapper* mapper() { return mapper_.get(); }
  const Mapper* mapper() const { return mapper_.get(); }
  const FrameAssembler& assembler() const { return assembler_; }
  const MapperOptions& options() const { return options_; }
  const ClassTable& classes() const { return classes_; }
  // Skip counts (reason key -> count) of the frames seen before Start.
  const std::map<std::string, std::uint64_t>& skipped_before_start() const {
    return skipped_before_start_;
  }

 private:
  void Process(std::vector<FrameInput> frames, std::vector<std::string> skipped,
               SessionUpdate* update);
  bool OdometryOverdue() const;

  MapperOptions options_;
  ClassTable classes_;
  double odometry_wait_s_;
  FrameAssembler assembler_;
  std::unique_ptr<Mapper> mapper_;
  std::map<std::string, std::uint64_t> skipped_before_start_;
  std::optional<double> newest_odometry_stamp_;
  std::optional<double> newest_frame_stamp_;
  std::optional<double> oldest_waiting_stamp_;
};

}  // namespace ipm_road_mapper
