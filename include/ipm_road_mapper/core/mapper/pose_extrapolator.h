// The corrected pose of the frames after the last solve (docs/backend.md, "Poses after a
// solve"): the window's pose step without the map, over the last 1.5 s of frames. Every
// frame of it is free with
//   - its pose prior (pose_prior_residual.h): a solved frame on its solved pose, a later one
//     on the odometry carried by the correction, T_map_odom * T_odom_base
//     (backend.pose_prior_sigma_*: the odometry's per-pose noise),
//   - the constant-twist prior (constant_twist_prior_residual.h: body-frame velocity and turn
//     rate change little, backend.motion_sigma_*) over each three consecutive frames; not the
//     window's map-frame motion prior, whose centripetal term pulled the tail outwards of
//     every curve (public_road: ~corrected_odom 0.63x -> ~0.56x the input's error).
// So the newest pose is the solved trajectory continued with the vehicle's smooth motion and
// the odometry's increments, not the newest odometry message with its own random error, and
// its velocity comes from the 1.5 s of frames, not from the two newest solved ones.
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <vector>

#include "ipm_road_mapper/core/backend/backend_options.h"
#include "ipm_road_mapper/core/map/road_map.h"

namespace ipm_road_mapper {

// The pose of frames.back(), `solved` being the newest frame a solve moved and T_map_odom
// its correction. T_map_odom * odometry when the tail cannot be solved (no motion prior, no
// frame before `solved`, a tail longer than backend.window_frames, a failed solve).
Eigen::Isometry3d ExtrapolateNewestPose(const std::vector<FrameRecord>& frames, std::size_t solved,
                                        const Eigen::Isometry3d& T_map_odom,
                                        const BackendOptions& options);

}  // namespace ipm_road_mapper
