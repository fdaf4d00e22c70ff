// Which rough extrinsic T_base_cam the mapper starts from, decided the same way by the
// offline runner (a bag's /tf_static) and the nodelet (the live tf tree): the config's
// input.extrinsic when given, else the transform base_frame -> camera frame (the masks'
// header.frame_id) looked up through a caller-supplied function. No ROS header.
#pragma once

#include <Eigen/Geometry>
#include <functional>
#include <string>

#include "ipm_road_mapper/core/mapper/input_options.h"

namespace ipm_road_mapper {

// Looks up T_parent_child (maps child points into parent). Empty on success, else why not.
using TransformLookup = std::function<std::string(
    const std::string& parent_frame, const std::string& child_frame, Eigen::Isometry3d* T)>;

// The chosen extrinsic and a one-line statement of where it came from, e.g.
// "config input.extrinsic" or "/tf_static base_link -> camera_optical".
struct ExtrinsicChoice {
  Eigen::Isometry3d T_base_cam = Eigen::Isometry3d::Identity();
  std::string source;
};

// Chooses the extrinsic (see the file comment); `lookup_name` names the lookup in the
// source line ("tf", "/tf_static"). Empty on success, otherwise one line: no camera frame,
// the lookup's error, or a transform that is not a finite rigid motion.
std::string ChooseExtrinsic(const InputOptions& input, const std::string& camera_frame,
                            const TransformLookup& lookup, const std::string& lookup_name,
                            ExtrinsicChoice* choice);

}  // namespace ipm_road_mapper
