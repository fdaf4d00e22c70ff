// Pairing masks with their camera_info while a bag is streamed (docs/design.md §2: masks and
// camera_info share a stamp): CameraInfoTable keeps the camera_infos read so far by stamp,
// CameraInfoPairing holds each mask until its match cannot change any more. Sync "exact"
// needs the identical stamp; "approximate" takes the nearest camera_info within half a frame
// period. Used by the offline runner (map_from_bag); errors are skip reasons, never
// exceptions.
#pragma once

#include <ros/time.h>
#include <rosbag/bag.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

#include <cstddef>
#include <deque>
#include <string>
#include <vector>

#include "ipm_road_mapper/core/geometry/pinhole_camera.h"

namespace ipm_road_mapper {

// The camera_infos of one topic read so far, by stamp (see the file comment).
class CameraInfoTable {
 public:
  // "approximate" window used when the period is unknown (fewer than 2 camera_infos).
  static constexpr double kDefaultTolerance_s = 0.05;
  // A camera_info older than the newest by more than this starts a new stream (a bag loop).
  static constexpr double kTimeJump_s = 0.01;
  // Camera_infos older than the newest by more than this are dropped (flat memory).
  static constexpr double kRetention_s = 10.0;

  // An empty table; `approximate_tolerance_s` is the "approximate" sync window.
  explicit CameraInfoTable(double approximate_tolerance_s = kDefaultTolerance_s);

  // Half the median period between the header stamps of the first `sample` messages of
  // the topic; only those are read (a 1 GB bag is not read through to start mapping); an
  // unreadable one (a corrupt chunk) ends the sample and sets *read_failed (the bag should then
  // be reopened before it is read again). kDefaultTolerance_s with fewer than 2 distinct stamps.
  static double ToleranceFromFirstMessages(const rosbag::Bag& bag, const std::string& topic,
                                           std::size_t sample = 20, bool* read_failed = nullptr);

  // Adds a camera_info (kept sorted by stamp; one that does not convert is kept with its
  // error, so a mask paired with it reports it). One older than the newest by more than
  // kTimeJump_s clears the table first; entries older than the newest by more than
  // kRetention_s are dropped.
  void Add(const sensor_msgs::CameraInfo& info);

  // True when a camera_info stamped at or after `stamp` is in the table: for a stream in
  // stamp order, no later camera_info can change Match's answer for `stamp`.
  bool Covers(const ros::Time& stamp) const;

  // The intrinsics for a mask stamped `stamp` (compared as ros::Time, not as a double, so
  // "exact" is exact). Empty on success, otherwise a skip reason "no_camera_info: ..." or
  // "bad_camera_info: ...".
  std::string Match(const ros::Time& stamp, bool exact, CameraIntrinsics* intrinsics) const;

  // Camera_infos kept now.
  std::size_t size() const { return entries_.size(); }
  // Half the median camera_info period (the "approximate" window), s.
  double approximate_tolerance_s() const { return approximate_tolerance_s_; }

 private:
  struct Entry {
    ros::Time stamp;
    CameraIntrinsics intrinsics;
    std::string error;  // conversion error, empty when usable
  };
  std::deque<Entry> entries_;  // sorted by stamp
  double approximate_tolerance_s_;
};

// A mask and its camera_info match: `camera` is valid when `error` is empty, else `error`
// is the frame's skip reason.
struct PairedMask {
  sensor_msgs::Image::ConstPtr mask;
  CameraIntrinsics camera;
  std::string error;
};

// Masks in bag order, each held until its match is final: a camera_info at or after its
// stamp has been read (CameraInfoTable::Covers), more than `max_waiting` masks wait (the
// oldest is decided with what is there), or the input ended (Flush). Masks leave in the
// order they came.
class CameraInfoPairing {
 public:
  CameraInfoPairing(CameraInfoTable table, bool exact, std::size_t max_waiting = 50);

  // Adds a camera_info; the masks it decides are appended to *ready.
  void AddCameraInfo(const sensor_msgs::CameraInfo& info, std::vector<PairedMask>* ready);

  // Adds a mask; the masks decided now (this one too when its camera_info is there) are
  // appended to *ready.
  void AddMask(sensor_msgs::Image::ConstPtr mask, std::vector<PairedMask>* ready);

  // End of input: decides every waiting mask with the camera_infos read.
  void Flush(std::vector<PairedMask>* ready);

  const CameraInfoTable& table() const { return table_; }
  // Masks waiting for their camera_info.
  std::size_t waiting() const { return waiting_.size(); }

 private:
  // Decides the oldest waiting mask.
  void DecideFront(std::vector<PairedMask>* ready);
  // Decides waiting masks from the oldest while they are covered or too many wait.
  void DecideReady(std::vector<PairedMask>* ready);

  CameraInfoTable table_;
  bool exact_;
  std::size_t max_waiting_;
  std::deque<sensor_msgs::Image::ConstPtr> waiting_;
};

}  // namespace ipm_road_mapper
