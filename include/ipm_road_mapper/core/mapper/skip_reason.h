// Why a frame was not used: one enum for every layer (the Mapper's validation, the frame
// assembler, the runners), so that the counters, the diagnostics and the summaries share one
// vocabulary. Counter keys and messages keep the snake_case names ("bad_mask: <detail>").
#pragma once

#include <optional>
#include <string>

namespace ipm_road_mapper {

enum class SkipReason {
  // Mapper::ProcessFrame's validation.
  kBadStamp,   // stamp not finite
  kTimeJump,   // stamp not after the last used frame's
  kBadCamera,  // intrinsics invalid
  kBadMask,    // not CV_16UC1 of the camera's size
  kBadPose,    // odometry pose not finite or not a rotation
  // The frame assembler (odometry at the mask stamp).
  kInvalidStamp,
  kOutOfOrderFrame,
  kNoOdometry,
  kQueueOverflow,
  kReset,
  // The runners (map_from_bag, the nodelet) before a frame exists.
  kNoExtrinsic,
  kBadMaskEncoding,
  kBadMaskMessage,
  kBadCameraInfo,
  kNoCameraInfo,
};

// The counter key, e.g. "bad_mask".
const char* ToString(SkipReason reason);
// The reason of a counter key; nullopt for a key no layer produces.
std::optional<SkipReason> ParseSkipReason(const std::string& key);
// "<key>: <detail>" (or the key alone when detail is empty): the text of a skipped frame.
std::string SkipText(SkipReason reason, const std::string& detail);

}  // namespace ipm_road_mapper
