#include "ipm_road_mapper/core/mapper/marking_pixel_agreement.h"

#include <algorithm>
#include <cmath>

namespace ipm_road_mapper {

bool PixelsAgree(const Ipm& ipm, const IpmErrorModel& error_model, double gate_sigmas,
                 const std::vector<FrameRecord>& frames, const MarkingElement& model,
                 const MarkingElement& viewed) {
  const double fy = ipm.camera().intrinsics().fy;
  const double sigma_px =
      std::hypot(error_model.pixel_error_px.norm(), fy * error_model.pitch_sigma_rad);
  const double gate_px = gate_sigmas * sigma_px;
  std::vector<double> errors;
  for (auto it = viewed.history.rbegin(); it != viewed.history.rend(); ++it) {
    if (errors.size() >= kMaxAgreementViews) break;
    if (!it->Complete() || it->frame_index >= frames.size()) continue;
    const Eigen::Isometry3d T_base_map = frames[it->frame_index].T_map_base.inverse();
    Eigen::Vector2d predicted = Eigen::Vector2d::Zero(), measured = Eigen::Vector2d::Zero();
    bool projects = true;
    for (int i = 0; i < 4 && projects; ++i) {
      Eigen::Vector2d uv;
      projects =
          ipm.BaseToPixel(T_base_map * model.corners_map[i], &uv) && it->corners_uv[i].allFinite();
      predicted += 0.25 * uv;
      measured += 0.25 * it->corners_uv[i];
    }
    if (projects) errors.push_back((predicted - measured).norm());
  }
  if (errors.empty()) return false;
  std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
  return errors[errors.size() / 2] <= gate_px;
}

}  // namespace ipm_road_mapper
