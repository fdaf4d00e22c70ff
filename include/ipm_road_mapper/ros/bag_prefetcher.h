// Reads a bag's mapper input (masks, odometry and camera_info, in bag order) in an owned
// thread, ahead of the consumer, so that mapping starts with the first messages and the bag
// is read once: chunk decompression and deserialization (about half of map_from_bag's
// time on the synthetic drives) overlap the mapping. A bounded queue keeps memory flat (a
// 1280x720 mask is 1.8 MB); the thread is always joined, and an error while reading is
// re-thrown to the consumer in order, after the messages read before it.
#pragma once

#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <exception>
#include <mutex>
#include <string>
#include <thread>

namespace ipm_road_mapper {

class BagPrefetcher {
 public:
  // The topic a message came from.
  enum class Kind { kMask, kOdometry, kCameraInfo };

  // One message of the bag. For a message that is not of the topic's type or does not
  // deserialize, the pointer of its kind is null (the consumer counts it).
  struct Item {
    Kind kind = Kind::kMask;
    sensor_msgs::Image::ConstPtr mask;
    nav_msgs::Odometry::ConstPtr odometry;
    sensor_msgs::CameraInfo::ConstPtr camera_info;
  };

  // The topics to read; an empty camera_info_topic is not read.
  struct Topics {
    std::string mask, odometry, camera_info;
  };

  // Starts reading the topics of the open bag (which must outlive this); at most
  // `capacity` messages wait for the consumer.
  BagPrefetcher(const rosbag::Bag& bag, const Topics& topics, std::size_t capacity = 16);
  ~BagPrefetcher();  // stops and joins the reader
  BagPrefetcher(const BagPrefetcher&) = delete;
  BagPrefetcher& operator=(const BagPrefetcher&) = delete;

  // The next message; false at the end of the bag. Re-throws the reader's exception (e.g. a
  // corrupt chunk) once the messages before it are consumed.
  bool Next(Item* item);

 private:
  void Read(const rosbag::Bag& bag, const Topics& topics);
  // Deserializes one message of a known topic into an Item (null payload on failure).
  static Item Deserialize(const rosbag::MessageInstance& message, const Topics& topics);

  const std::size_t capacity_;
  std::mutex mutex_;
  std::condition_variable not_empty_, not_full_;
  std::deque<Item> queue_;
  bool done_ = false;      // the reader finished (or failed)
  bool stopping_ = false;  // the consumer is gone
  std::exception_ptr error_;
  std::thread reader_;
};

}  // namespace ipm_road_mapper
