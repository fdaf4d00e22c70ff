// Streams a bag's mapper input through a MappingSession in one pass, as map_from_bag runs
// it: masks, odometry and camera_info read and deserialized ahead in the BagPrefetcher's
// thread, each mask paired with its camera_info (CameraInfoPairing) and handed to the
// session in bag order, so mapping starts with the first messages. Only the first
// camera_infos are read beforehand (the "approximate" window). A message that cannot be read
// (a corrupt chunk) is skipped and counted, and mapping goes on after it. Offline only.
#pragma once

#include <rosbag/bag.h>

#include <cstddef>
#include <functional>
#include <optional>

#include "ipm_road_mapper/pipeline/mapper_config.h"
#include "ipm_road_mapper/pipeline/mapping_session.h"
#include "ipm_road_mapper/ros/bag_read_loss.h"

namespace ipm_road_mapper {

// What the caller hears while the bag is mapped (each callback may be empty).
struct BagMappingCallbacks {
  // After every frame (a mask message) was handed to the session, used or skipped:
  // `frame` is its 0-based index, `stamp` its header stamp (s; NaN when the message did not
  // deserialize).
  std::function<void(std::size_t frame, double stamp)> frame_done;
  // Once, when the Mapper used its first frame.
  std::function<void()> first_frame_mapped;
};

// What MapBag read.
struct BagMappingResult {
  // Mask messages handed to the session (used or skipped), unreadable ones included.
  std::size_t frames_read = 0;
  // The messages that could not be read; each lost mask is also a frame skipped as
  // `unreadable_chunk`.
  BagReadLoss lost;
};

// Maps the `topics` (ros: section) of the open bag into the started session, then finishes it
// (waiting frames decided, the last window solved). A message whose chunk cannot be read is
// skipped and counted in the result; other rosbag errors throw rosbag::BagException (after
// the messages before it).
BagMappingResult MapBag(const rosbag::Bag& bag, const RosOptions& topics, MappingSession* session,
                        const BagMappingCallbacks& callbacks);

}  // namespace ipm_road_mapper
