#include "ipm_road_mapper/ros/bag_prefetcher.h"

#include <ros/serialization.h>
#include <rosbag/view.h>

#include <utility>

namespace ipm_road_mapper {

BagPrefetcher::BagPrefetcher(const rosbag::Bag& bag, const std::string& mask_topic,
                             const std::string& odom_topic, std::size_t capacity)
    : capacity_(capacity < 1 ? 1 : capacity) {
  reader_ =
      std::thread([this, &bag, mask_topic, odom_topic] { Read(bag, mask_topic, odom_topic); });
}

BagPrefetcher::~BagPrefetcher() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  not_full_.notify_all();
  reader_.join();
}

void BagPrefetcher::Read(const rosbag::Bag& bag, const std::string& mask_topic,
                         const std::string& odom_topic) {
  try {
    rosbag::View view(bag, rosbag::TopicQuery({mask_topic, odom_topic}));
    for (const rosbag::MessageInstance& message : view) {
      Item item;
      item.is_mask = message.getTopic() == mask_topic;
      // The type is checked first (instantiate() would deserialize another type's bytes);
      // a message that does not deserialize (truncated, or written under another type's
      // connection) is handed on as null too, and reading goes on.
      try {
        if (item.is_mask) {
          if (message.getDataType() == ros::message_traits::DataType<sensor_msgs::Image>::value()) {
            item.mask = message.instantiate<sensor_msgs::Image>();
          }
        } else if (message.getDataType() ==
                   ros::message_traits::DataType<nav_msgs::Odometry>::value()) {
          item.odometry = message.instantiate<nav_msgs::Odometry>();
        }
      } catch (const ros::serialization::StreamOverrunException&) {
        item.mask.reset();
        item.odometry.reset();
      }
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
