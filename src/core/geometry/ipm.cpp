#include "ipm_road_mapper/core/geometry/ipm.h"

namespace ipm_road_mapper {

const char* ToString(IpmStatus status) {
  switch (status) {
    case IpmStatus::kOk:
      return "ok";
    case IpmStatus::kAboveHorizon:
      return "above_horizon";
    case IpmStatus::kBeyondRange:
      return "beyond_range";
  }
  return "unknown";
}

Ipm::Ipm(const PinholeCamera& camera, const Eigen::Isometry3d& T_base_cam, double max_range_m)
    : camera_(camera),
      T_base_cam_(T_base_cam),
      T_cam_base_(T_base_cam.inverse()),
      max_range_m_(max_range_m) {}

IpmStatus Ipm::PixelToGround(const Eigen::Vector2d& uv, Eigen::Vector3d* p_base) const {
  Eigen::Vector3d p;
  const Eigen::Matrix3d R = T_base_cam_.linear();
  const Eigen::Vector3d t = T_base_cam_.translation();
  if (!GroundPoint<double>(camera_, R, t, uv, &p)) return IpmStatus::kAboveHorizon;
  if (p.head<2>().norm() > max_range_m_) return IpmStatus::kBeyondRange;
  *p_base = p;
  return IpmStatus::kOk;
}

bool Ipm::BaseToPixel(const Eigen::Vector3d& p_base, Eigen::Vector2d* uv) const {
  return camera_.Project<double>(T_cam_base_ * p_base, uv);
}

Eigen::Matrix3d Ipm::HomographyGroundToImage() const {
  const Eigen::Matrix3d R_cam_base = T_cam_base_.linear();
  Eigen::Matrix3d M;
  M.col(0) = R_cam_base.col(0);
  M.col(1) = R_cam_base.col(1);
  M.col(2) = T_cam_base_.translation();  // = -R_cam_base * t_base_cam
  return camera_.K() * M;
}

}  // namespace ipm_road_mapper
