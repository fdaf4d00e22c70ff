// Which rough extrinsic T_base_cam the mapper starts from, decided the same way by the
// offline runner (a bag's /tf_static) and the nodelet (the live tf tree): the config's
// input.extrinsic when given, else the transform base_frame -> camera frame (the masks'
// header.frame_id) looked up through a caller-supplied function. No ROS header.
#pragma once

#include <Eigen/Geometry>
#include <array>
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

// The refined extrinsic as a calibration for the next run (map_from_bag --calibration-out):
// a YAML config overlay whose input.extrinsic (xyz, rpy_deg) LoadInputOptions reads back,
// with `base:` set to base_config when it is not empty (so the file is a complete config:
// that config with the refined extrinsic), and in comments the 1-sigma uncertainty and the
// observed axes, the covariance, a tf2_ros static_transform_publisher line and a URDF joint.
struct Calibration {
  Eigen::Isometry3d T_base_cam = Eigen::Isometry3d::Identity();
  // roll, pitch, yaw about base_link (rad), x, y, z (m); see VectorMap::T_base_cam_covariance.
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
  std::array<bool, 6> observed{};
  std::string base_frame = "base_link";
  std::string camera_frame = "camera_optical_frame";
  std::string note;  // one line on where it came from (bag, config)
};

// The file's text (see above).
std::string CalibrationYaml(const Calibration& calibration, const std::string& base_config);

// Writes it atomically; empty on success, else one line why not.
std::string WriteCalibrationFile(const std::string& path, const Calibration& calibration,
                                 const std::string& base_config);

}  // namespace ipm_road_mapper
