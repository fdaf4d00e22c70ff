#include "ipm_road_mapper/ros/bag_prefetcher.h"

#include <ros/serialization.h>
#include <rosbag/exceptions.h>
#include <rosbag/view.h>

#include <exception>
#include <map>
#include <memory>
#include <string>
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

// Why a message could not be read, never empty.
std::string ReadError(const std::exception& e) {
  const std::string what = e.what();
  return what.empty() ? "unreadable message" : what;
}

}  // namespace

BagPrefetcher::BagPrefetcher(const rosbag::Bag& bag, const Topics& topics, std::size_t capacity,
                             bool reopen_first)
    : capacity_(capacity < 1 ? 1 : capacity) {
  reader_ = std::thread([this, &bag, topics, reopen_first] { Read(bag, topics, reopen_first); });
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
  item.bag_time_s = message.getTime().toSec();
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
    // Bytes read, but not a message of this type: a bad message, counted by the consumer.
  } catch (const rosbag::BagException& e) {
    // The chunk holding it is corrupt (ROSLZ4_DATA_ERROR, a bad record header, ...).
    item.read_error = ReadError(e);
  } catch (const std::exception& e) {
    // A corrupt size field can ask for an absurd buffer (std::bad_alloc, std::length_error).
    item.read_error = ReadError(e);
  }
  return item;
}

bool BagPrefetcher::Push(Item item) {
  std::unique_lock<std::mutex> lock(mutex_);
  not_full_.wait(lock, [this] { return stopping_ || queue_.size() < capacity_; });
  if (stopping_) return false;
  queue_.push_back(std::move(item));
  lock.unlock();
  not_empty_.notify_one();
  return true;
}

void BagPrefetcher::Read(const rosbag::Bag& bag, const Topics& topics, bool reopen_first) {
  try {
    std::vector<std::string> names = {topics.mask, topics.odometry};
    if (!topics.camera_info.empty()) names.push_back(topics.camera_info);
    // After a read error the Bag's one-chunk cache may hold the bad chunk's bytes under the
    // name of the last good chunk (rosbag updates the name only after a successful
    // decompression), so a later message of that chunk would deserialize garbage. The
    // reading then goes on in a freshly opened Bag, from the failed message's record time,
    // skipping the messages of that time already handled: per topic, as many as were
    // handled (a new View may order messages of equal time differently across topics, but
    // keeps the record order within one).
    std::unique_ptr<rosbag::Bag> reopened;
    ros::Time resume_time = ros::TIME_MIN;
    ros::Time last_time;
    std::map<std::string, std::size_t> handled_at_last_time;  // per topic
    bool restart = true, after_error = reopen_first;
    while (restart) {
      restart = false;
      if (after_error) {
        reopened.reset();
        reopened = std::make_unique<rosbag::Bag>(bag.getFileName(), rosbag::bagmode::Read);
      }
      const rosbag::Bag& reading = reopened ? *reopened : bag;
      rosbag::View view(reading, rosbag::TopicQuery(names), resume_time);
      std::map<std::string, std::size_t> skip;
      if (reopened) skip = handled_at_last_time;
      for (const rosbag::MessageInstance& message : view) {
        const ros::Time time = message.getTime();
        if (time == resume_time) {
          std::size_t& to_skip = skip[message.getTopic()];
          if (to_skip > 0) {
            --to_skip;
            continue;
          }
        }
        if (time != last_time) handled_at_last_time.clear();
        ++handled_at_last_time[message.getTopic()];
        last_time = time;
        Item item = Deserialize(message, topics);
        const bool failed = !item.read_error.empty();
        if (!Push(std::move(item))) return;
        if (failed) {
          resume_time = time;
          restart = after_error = true;
          break;
        }
      }
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
