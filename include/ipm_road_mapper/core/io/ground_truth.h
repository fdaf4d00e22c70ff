// Ground truth of a synthetic drive (written by generate_drive, read by evaluate_map and
// the tests). The JSON form is specified in docs/file_formats.md.
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "ipm_road_mapper/core/geometry/pinhole_camera.h"
#include "ipm_road_mapper/core/geometry/rigid_transform.h"

namespace ipm_road_mapper {

// Current version of the ground-truth JSON format.
constexpr int kGroundTruthFormatVersion = 1;

// A ground marking's true bounding rectangle (corners counter-clockwise seen from above).
struct GroundTruthMarking {
  int id = 0;
  int class_id = 0;
  std::string class_name;
  std::array<Eigen::Vector3d, 4> corners_map;
  Eigen::Vector3d center_map = Eigen::Vector3d::Zero();
  int visible_frames = 0;  // frames whose mask holds it (recall counts only seen markings)
};

// A true lane line as a dense polyline (a point every 0.1 m along the line's center).
struct GroundTruthLane {
  int id = 0;
  int class_id = 0;
  std::string class_name;
  std::string style;  // "solid" or "dashed"
  std::vector<Eigen::Vector3d> points_map;
};

// One camera frame: its stamp, the true vehicle pose and the odometry the mapper got.
struct GroundTruthFrame {
  double stamp = 0.0;
  Eigen::Isometry3d T_map_base_true = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d T_map_base_odom = Eigen::Isometry3d::Identity();
};

// Everything a synthetic drive knows to be true.
struct GroundTruth {
  std::string scenario;
  std::uint32_t seed = 0;
  double frame_rate_hz = 20.0;
  CameraIntrinsics camera;
  Eigen::Isometry3d T_base_cam_true = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d T_base_cam_rough = Eigen::Isometry3d::Identity();
  std::vector<GroundTruthMarking> markings;
  std::vector<GroundTruthLane> lanes;
  std::vector<GroundTruthFrame> frames;
};

// Writes the ground truth as JSON (deterministic: same input, same bytes). Throws
// std::runtime_error when the file cannot be written.
void SaveGroundTruthJson(const GroundTruth& gt, const std::string& path);

// Reads a ground-truth file. Throws MapFormatError (see vector_map.h) on any problem.
GroundTruth LoadGroundTruthJson(const std::string& path);

}  // namespace ipm_road_mapper
