// Reads a bag's mapper input (masks, odometry and camera_info, in bag order) in an owned
// thread, ahead of the consumer, so that mapping starts with the first messages and the bag
// is read once: chunk decompression and deserialization (about half of map_from_bag's
// time on the synthetic drives) overlap the mapping. A bounded queue keeps memory flat (a
// 1280x720 mask is 1.8 MB); the thread is always joined. A message whose bytes cannot be read
// (a corrupt chunk: a bad LZ4/BZ2 block, a bad record) is handed on with its read error and
// reading goes on with the next message (the bag's index, read at open, still lists them; the
// rest is read from a freshly opened copy of the bag, see Read); any
// other error is re-thrown to the consumer in order, after the messages read before it.
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
  // deserialize, the pointer of its kind is null (the consumer counts it); for one that
  // could not be read from the bag at all, read_error says why too.
  struct Item {
    Kind kind = Kind::kMask;
    double bag_time_s = 0.0;  // the record time (from the index, known even when unreadable)
    std::string read_error;   // non-empty: the bytes could not be read (corrupt chunk)
    sensor_msgs::Image::ConstPtr mask;
    nav_msgs::Odometry::ConstPtr odometry;
    sensor_msgs::CameraInfo::ConstPtr camera_info;
  };

  // The topics to read; an empty camera_info_topic is not read.
  struct Topics {
    std::string mask, odometry, camera_info;
  };

  // Starts reading the topics of the open bag (which must outlive this); at most
  // `capacity` messages wait for the consumer. `reopen_first`: read from a freshly opened
  // copy of the bag from the start (the caller's Bag had a read error, its chunk cache may be
  // wrong).
  BagPrefetcher(const rosbag::Bag& bag, const Topics& topics, std::size_t capacity = 16,
                bool reopen_first = false);
  ~BagPrefetcher();  // stops and joins the reader
  BagPrefetcher(const BagPrefetcher&) = delete;
  BagPrefetcher& operator=(const BagPrefetcher&) = delete;

  // The next message; false at the end of the bag. Re-throws the reader's exception (e.g. a
  // corrupt chunk) once the messages before it are consumed.
  bool Next(Item* item);

 private:
  // The reader thread: the bag's messages of `topics` into the queue (see the file comment).
  void Read(const rosbag::Bag& bag, const Topics& topics, bool reopen_first);
  // Queues one item, waiting for room; false when the consumer is gone.
  bool Push(Item item);
  // Deserializes one message of a known topic into an Item (null payload on failure, with
  // read_error when the bag could not deliver its bytes).
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
