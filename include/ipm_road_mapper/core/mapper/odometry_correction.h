// The correction of the odometry after a solve, T_map_odom (REP-105 map -> odom), fitted over
// the frames the solve moved instead of taken from one of them (docs/backend.md, "Poses after
// a solve"). One frame's correction T_map_base * T_odom_base^-1 carries that frame's own
// odometry error (the per-message jitter), and every frame it is carried to inherits it: on
// public_road's 8 cm jitter the carried poses then err by sqrt(2) times the jitter. Over the
// solved frames i:
//   R = the chordal mean of the rotation corrections R_map_base_i R_odom_base_i^T,
//   t = mean(t_map_base_i) - R mean(t_odom_base_i)
// so the jitter of n frames averages down by sqrt(n) while a slow drift (seconds) is followed
// as far as the window reaches.
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <vector>

#include "ipm_road_mapper/core/map/road_map.h"

namespace ipm_road_mapper {

// T_map_odom fitted over frames[i] for i in `solved` (their T_map_base against their
// T_map_base_odom); identity when `solved` is empty. Indices must be valid.
Eigen::Isometry3d FitOdometryCorrection(const std::vector<FrameRecord>& frames,
                                        const std::vector<std::size_t>& solved);

}  // namespace ipm_road_mapper
