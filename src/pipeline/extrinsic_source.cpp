#include "ipm_road_mapper/pipeline/extrinsic_source.h"

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

}  // namespace ipm_road_mapper
