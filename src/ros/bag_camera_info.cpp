#include "ipm_road_mapper/ros/bag_camera_info.h"

#include <ros/serialization.h>
#include <rosbag/view.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <utility>

#include "ipm_road_mapper/ros/msg_conversion.h"

namespace ipm_road_mapper {
namespace {

std::string FormatSeconds(double s) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(3) << s << " s";
  return out.str();
}

}  // namespace

CameraInfoTable::CameraInfoTable(double approximate_tolerance_s)
    : approximate_tolerance_s_(approximate_tolerance_s) {}

double CameraInfoTable::ToleranceFromFirstMessages(const rosbag::Bag& bag, const std::string& topic,
                                                   std::size_t sample, bool* read_failed) {
  if (read_failed) *read_failed = false;
  std::vector<ros::Time> stamps;
  rosbag::View view(bag, rosbag::TopicQuery(topic));
  for (const rosbag::MessageInstance& message : view) {
    if (stamps.size() >= sample) break;  // the view reads no further chunk
    if (message.getDataType() != ros::message_traits::DataType<sensor_msgs::CameraInfo>::value()) {
      continue;
    }
    try {
      const auto info = message.instantiate<sensor_msgs::CameraInfo>();
      if (info) stamps.push_back(info->header.stamp);
    } catch (const ros::serialization::StreamOverrunException&) {
      // Not a CameraInfo: the period comes from the others.
    } catch (const std::exception&) {
      // A corrupt chunk: the bag's chunk cache may now be wrong (bag_prefetcher.cpp), so no
      // further message is read from it.
      if (read_failed) *read_failed = true;
      break;
    }
  }
  std::sort(stamps.begin(), stamps.end());
  std::vector<double> periods;
  for (std::size_t i = 1; i < stamps.size(); ++i) {
    const double dt = (stamps[i] - stamps[i - 1]).toSec();
    if (dt > 0.0) periods.push_back(dt);
  }
  if (periods.empty()) return kDefaultTolerance_s;
  std::nth_element(periods.begin(), periods.begin() + periods.size() / 2, periods.end());
  return 0.5 * periods[periods.size() / 2];
}

void CameraInfoTable::Add(const sensor_msgs::CameraInfo& info) {
  Entry entry;
  entry.stamp = info.header.stamp;
  entry.error = CameraInfoToIntrinsics(info, &entry.intrinsics);
  if (!entries_.empty() && (entries_.back().stamp - entry.stamp).toSec() > kTimeJump_s) {
    entries_.clear();  // a new stream (bag loop): the old stamps would pair the wrong frames
  }
  const auto after =
      std::upper_bound(entries_.begin(), entries_.end(), entry.stamp,
                       [](const ros::Time& s, const Entry& e) { return s < e.stamp; });
  entries_.insert(after, std::move(entry));
  const ros::Time newest = entries_.back().stamp;
  while ((newest - entries_.front().stamp).toSec() > kRetention_s) entries_.pop_front();
}

bool CameraInfoTable::Covers(const ros::Time& stamp) const {
  return !entries_.empty() && entries_.back().stamp >= stamp;
}

std::string CameraInfoTable::Match(const ros::Time& stamp, bool exact,
                                   CameraIntrinsics* intrinsics) const {
  if (entries_.empty()) return "no_camera_info: no camera_info in the bag";
  const auto after =
      std::lower_bound(entries_.begin(), entries_.end(), stamp,
                       [](const Entry& e, const ros::Time& s) { return e.stamp < s; });
  const Entry* best = nullptr;
  double best_dt = 0.0;
  for (auto it : {after - (after != entries_.begin() ? 1 : 0), after}) {
    if (it == entries_.end()) continue;
    const double dt = std::abs((it->stamp - stamp).toSec());
    if (!best || dt < best_dt) {
      best = &*it;
      best_dt = dt;
    }
  }
  const bool matched = exact ? best->stamp == stamp : best_dt <= approximate_tolerance_s_;
  if (!matched) {
    return "no_camera_info: none " +
           (exact ? std::string("with the identical stamp")
                  : "within " + FormatSeconds(approximate_tolerance_s_)) +
           " for the mask at " + FormatSeconds(stamp.toSec()) + " (nearest " +
           FormatSeconds(best_dt) + " away)";
  }
  if (!best->error.empty()) return "bad_camera_info: " + best->error;
  *intrinsics = best->intrinsics;
  return "";
}

CameraInfoPairing::CameraInfoPairing(CameraInfoTable table, bool exact, std::size_t max_waiting)
    : table_(std::move(table)), exact_(exact), max_waiting_(max_waiting) {}

void CameraInfoPairing::AddCameraInfo(const sensor_msgs::CameraInfo& info,
                                      std::vector<PairedMask>* ready) {
  table_.Add(info);
  DecideReady(ready);
}

void CameraInfoPairing::AddMask(sensor_msgs::Image::ConstPtr mask, std::vector<PairedMask>* ready) {
  waiting_.push_back(std::move(mask));
  DecideReady(ready);
}

void CameraInfoPairing::Flush(std::vector<PairedMask>* ready) {
  while (!waiting_.empty()) DecideFront(ready);
}

void CameraInfoPairing::DecideFront(std::vector<PairedMask>* ready) {
  PairedMask paired;
  paired.mask = std::move(waiting_.front());
  waiting_.pop_front();
  paired.error = table_.Match(paired.mask->header.stamp, exact_, &paired.camera);
  ready->push_back(std::move(paired));
}

void CameraInfoPairing::DecideReady(std::vector<PairedMask>* ready) {
  while (!waiting_.empty() &&
         (waiting_.size() > max_waiting_ || table_.Covers(waiting_.front()->header.stamp))) {
    DecideFront(ready);
  }
}

}  // namespace ipm_road_mapper
