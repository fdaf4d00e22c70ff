// What the core needs to know about its input (config section `input`): the vehicle frame
// and an optional extrinsic that overrides tf / the bag's /tf_static. Read by both the
// offline runner and the nodelet, so the two agree. Topic names and the mask/camera_info
// sync policy are transport details: they live in the runners' `ros:` section (RosOptions).
#pragma once

#include <Eigen/Geometry>
#include <optional>
#include <string>

#include "ipm_road_mapper/core/io/yaml_options.h"

namespace ipm_road_mapper {

struct InputOptions {
  std::string base_frame = "base_link";
  // Rough extrinsic T_base_cam given in the config (xyz m, rpy deg of the optical frame in
  // base_link); when absent it comes from tf (/tf_static in a bag).
  std::optional<Eigen::Isometry3d> T_base_cam;
};

// Reads the `input` section (extrinsic as {xyz: [x,y,z], rpy_deg: [r,p,y]}); throws
// OptionsError naming the bad key.
InputOptions LoadInputOptions(OptionsReader reader);

}  // namespace ipm_road_mapper
