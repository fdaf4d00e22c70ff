#include "ipm_road_mapper/core/mapper/skip_reason.h"

#include <array>
#include <utility>

namespace ipm_road_mapper {
namespace {

constexpr std::array<std::pair<SkipReason, const char*>, 15> kNames{{
    {SkipReason::kBadStamp, "bad_stamp"},
    {SkipReason::kTimeJump, "time_jump"},
    {SkipReason::kBadCamera, "bad_camera"},
    {SkipReason::kBadMask, "bad_mask"},
    {SkipReason::kBadPose, "bad_pose"},
    {SkipReason::kInvalidStamp, "invalid_stamp"},
    {SkipReason::kOutOfOrderFrame, "out_of_order_frame"},
    {SkipReason::kNoOdometry, "no_odometry"},
    {SkipReason::kQueueOverflow, "queue_overflow"},
    {SkipReason::kReset, "reset"},
    {SkipReason::kNoExtrinsic, "no_extrinsic"},
    {SkipReason::kBadMaskEncoding, "bad_mask_encoding"},
    {SkipReason::kBadMaskMessage, "bad_mask_message"},
    {SkipReason::kBadCameraInfo, "bad_camera_info"},
    {SkipReason::kNoCameraInfo, "no_camera_info"},
}};

}  // namespace

const char* ToString(SkipReason reason) {
  for (const auto& [r, name] : kNames) {
    if (r == reason) return name;
  }
  return "unknown";
}

std::optional<SkipReason> ParseSkipReason(const std::string& key) {
  for (const auto& [r, name] : kNames) {
    if (key == name) return r;
  }
  return std::nullopt;
}

std::string SkipText(SkipReason reason, const std::string& detail) {
  return detail.empty() ? std::string(ToString(reason)) : ToString(reason) + (": " + detail);
}

}  // namespace ipm_road_mapper
