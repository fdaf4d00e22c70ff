#include "ipm_road_mapper/pipeline/extrinsic_source.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "ipm_road_mapper/core/backend/extrinsic_observability.h"
#include "ipm_road_mapper/core/geometry/rigid_transform.h"

namespace ipm_road_mapper {

std::string ChooseExtrinsic(const InputOptions& input, const std::string& camera_frame,
                            const TransformLookup& lookup, const std::string& lookup_name,
                            ExtrinsicChoice* choice) {
  if (input.T_base_cam) {
    choice->T_base_cam = *input.T_base_cam;
    choice->source = "config input.extrinsic";
    return "";
  }
  if (camera_frame.empty()) {
    return "no extrinsic: the masks have no header.frame_id and the config has no "
           "input.extrinsic";
  }
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  const std::string error = lookup ? lookup(input.base_frame, camera_frame, &T) : "no lookup";
  if (!error.empty()) {
    return "no extrinsic " + input.base_frame + " -> " + camera_frame + ": " + error;
  }
  if (!IsValidTransform(T)) {
    return "extrinsic " + input.base_frame + " -> " + camera_frame + " from " + lookup_name +
           " is not a finite rigid transform";
  }
  choice->T_base_cam = T;
  choice->source = lookup_name + " " + input.base_frame + " -> " + camera_frame;
  return "";
}

namespace {

// A number with enough digits to round-trip (%.9g: 1e-9 m, 2e-8 deg at these magnitudes).
std::string Number(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.9g", value);
  return text;
}

std::string Triple(const Eigen::Vector3d& v, const char* separator) {
  return Number(v.x()) + separator + Number(v.y()) + separator + Number(v.z());
}

}  // namespace

std::string CalibrationYaml(const Calibration& c, const std::string& base_config) {
  const Eigen::Vector3d xyz = c.T_base_cam.translation();
  const Eigen::Vector3d rpy = RpyFromRotation(c.T_base_cam.linear());
  const Eigen::Vector3d rpy_deg = rpy * 180.0 / M_PI;
  const Eigen::Quaterniond q(c.T_base_cam.linear());
  const Eigen::Matrix<double, 6, 1> sigma = c.covariance.diagonal().cwiseMax(0.0).cwiseSqrt();
  std::ostringstream s;
  s << "# ipm_road_mapper calibration: the refined extrinsic T_base_cam (" << c.camera_frame
    << " in " << c.base_frame << ").\n";
  if (!c.note.empty()) s << "# " << c.note << "\n";
  s << "# Use it as the config of the next run (--config this file; its input.extrinsic\n"
    << "# overrides the bag's /tf_static), or copy the input block into your config.\n"
    << "#\n"
    << "# 1-sigma: roll pitch yaw " << Triple(sigma.head<3>() * 180.0 / M_PI, " ") << " deg, x y z "
    << Triple(sigma.tail<3>(), " ") << " m\n"
    << "# observed by the data: " << ObservedAxesText(c.observed)
    << " (the other axes stayed at their prior)\n"
    << "# covariance (roll pitch yaw about base_link in rad, x y z in m), row-major:\n";
  for (int r = 0; r < 6; ++r) {
    s << "#   [";
    for (int col = 0; col < 6; ++col) s << (col ? ", " : "") << Number(c.covariance(r, col));
    s << "]\n";
  }
  s << "#\n"
    << "# tf2_ros (x y z qx qy qz qw parent child):\n"
    << "#   rosrun tf2_ros static_transform_publisher " << Triple(xyz, " ") << " " << Number(q.x())
    << " " << Number(q.y()) << " " << Number(q.z()) << " " << Number(q.w()) << " " << c.base_frame
    << " " << c.camera_frame << "\n"
    << "# URDF:\n"
    << "#   <joint name=\"" << c.base_frame << "_to_" << c.camera_frame << "\" type=\"fixed\">\n"
    << "#     <parent link=\"" << c.base_frame << "\"/>\n"
    << "#     <child link=\"" << c.camera_frame << "\"/>\n"
    << "#     <origin xyz=\"" << Triple(xyz, " ") << "\" rpy=\"" << Triple(rpy, " ") << "\"/>\n"
    << "#   </joint>\n";
  if (!base_config.empty()) s << "base: " << base_config << "\n";
  s << "input:\n"
    << "  extrinsic:\n"
    << "    xyz: [" << Triple(xyz, ", ") << "]\n"
    << "    rpy_deg: [" << Triple(rpy_deg, ", ") << "]\n";
  return s.str();
}

std::string WriteCalibrationFile(const std::string& path, const Calibration& calibration,
                                 const std::string& base_config) {
  const std::string temporary = path + ".tmp";
  {
    std::ofstream out(temporary);
    out << CalibrationYaml(calibration, base_config);
    if (!out) return path + ": cannot write";
  }
  std::error_code error;
  std::filesystem::rename(temporary, path, error);
  if (error) return path + ": cannot write: " + error.message();
  return "";
}

}  // namespace ipm_road_mapper
