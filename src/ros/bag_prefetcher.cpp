#include "ipm_road_mapper/ros/bag_prefetcher.h"

#include <ros/serialization.h>
#include <rosbag/view.h>

#include <utility>
#include <vector>

namespace ipm_road_mapper {
namespace {

// The message as M when the bag says it is one (instantiate() would deserialize another
// type's bytes), else null.
template <class M>
boost::shared_ptr<const M> InstantiateIf(const rosbag::MessageInstance& message) {
  if (message.getDataType() != ros::message_traits::DataType<M>::value()) return nullptr;
  return message.instantiate<M>();
}

}  // namespace

BagPrefetcher::BagPrefetcher(const rosbag::Bag& bag, const Topics& topics, std::size_t capacity)
    : capacity_(capacity < 1 ? 1 : capacity) {
  reader_ = std::thread([this, &bag, topics] { Read(bag, topics); });
}

BagPrefetcher::~BagPrefetcher() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  not_full_.notify_all();
  reader_.join();
}

BagPrefetcher::Item BagPrefetcher::Deserialize(const rosbag::MessageInstance& message,
                                               const Topics& topics) {
  Item item;
  const std::string& topic = message.getTopic();
  item.kind = topic == topics.mask       ? Kind::kMask
              : topic == topics.odometry ? Kind::kOdometry
                                         : Kind::kCameraInfo;
  // A message that does not deserialize (truncated, or written under another type's
  // connection) is handed on as null too, and reading goes on.
  try {
    switch (item.kind) {
      case Kind::kMask:
        item.mask = InstantiateIf<sensor_msgs::Image>(message);
        break;
      case Kind::kOdometry:
        item.odometry = InstantiateIf<nav_msgs::Odometry>(message);
        break;
      case Kind::kCameraInfo:
        item.camera_info = InstantiateIf<sensor_msgs::CameraInfo>(message);
        break;
    }
  } catch (const ros::serialization::StreamOverrunException&) {
    item.mask.reset();
    item.odometry.reset();
    item.camera_info.reset();
  }
  return item;
}

void BagPrefetcher::Read(const rosbag::Bag& bag, const Topics& topics) {
  try {
    std::vector<std::string> names = {topics.mask, topics.odometry};
    if (!topics.camera_info.empty()) names.push_back(topics.camera_info);
    rosbag::View view(bag, rosbag::TopicQuery(names));
    for (const rosbag::MessageInstance& message : view) {
      Item item = Deserialize(message, topics);
      std::unique_lock<std::mutex> lock(mutex_);
      not_full_.wait(lock, [this] { return stopping_ || queue_.size() < capacity_; });
      if (stopping_) return;
      queue_.push_back(std::move(item));
      lock.unlock();
      not_empty_.notify_one();
    }
  } catch (...) {
    std::lock_guard<std::mutex> lock(mutex_);
    error_ = std::current_exception();
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    done_ = true;
  }
  not_empty_.notify_one();
}

bool BagPrefetcher::Next(Item* item) {
  std::unique_lock<std::mutex> lock(mutex_);
  not_empty_.wait(lock, [this] { return done_ || !queue_.empty(); });
  if (!queue_.empty()) {
    *item = std::move(queue_.front());
    queue_.pop_front();
    lock.unlock();
    not_full_.notify_one();
    return true;
  }
  if (error_) {
    std::exception_ptr error = error_;
    error_ = nullptr;
    std::rethrow_exception(error);
  }
  return false;
}

}  // namespace ipm_road_mapper
