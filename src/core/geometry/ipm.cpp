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

Ipm::Ipm(const PinholeCamera& camera, const Eigen::Isometry3d& T_base_cam, double max_range_m,
         const RoadPlane& ground_base)
    : Ipm(camera, T_base_cam, max_range_m) {
  ground_base_.point = ground_base.point;
  ground_base_.normal = ground_base.normal.normalized();
  if (ground_base_.normal.z() < 0.0) ground_base_.normal = -ground_base_.normal;
  flat_ = ground_base_.point.isZero(0.0) && ground_base_.normal == Eigen::Vector3d::UnitZ();
}

IpmStatus Ipm::PixelToGround(const Eigen::Vector2d& uv, Eigen::Vector3d* p_base) const {
  Eigen::Vector3d p;
  const Eigen::Matrix3d R = T_base_cam_.linear();
  const Eigen::Vector3d t = T_base_cam_.translation();
  if (flat_) {
    if (!GroundPoint<double>(camera_, R, t, uv, &p)) return IpmStatus::kAboveHorizon;
  } else {
    const Eigen::Vector2d xy = camera_.UndistortToNormalized(uv);
    const Eigen::Vector3d ray_base = R * Eigen::Vector3d(xy.x(), xy.y(), 1.0);
    const Eigen::Vector3d& n = ground_base_.normal;
    const double descent = n.dot(ray_base);
    if (descent > -kMinRayDescent * ray_base.norm()) return IpmStatus::kAboveHorizon;
    const double lambda = n.dot(ground_base_.point - t) / descent;
    if (!(lambda > 0.0)) return IpmStatus::kAboveHorizon;  // the camera is below the plane
    p = t + lambda * ray_base;
  }
  if (p.head<2>().norm() > max_range_m_) return IpmStatus::kBeyondRange;
  *p_base = p;
  return IpmStatus::kOk;
}

Eigen::Vector3d Ipm::OnGround(const Eigen::Vector2d& xy_base) const {
  if (flat_) return Eigen::Vector3d(xy_base.x(), xy_base.y(), 0.0);
  // n . (p - p0) = 0 solved for z (the normal points up: n_z > 0).
  const Eigen::Vector3d& n = ground_base_.normal;
  const Eigen::Vector3d& p0 = ground_base_.point;
  const double z =
      p0.z() - (n.x() * (xy_base.x() - p0.x()) + n.y() * (xy_base.y() - p0.y())) / n.z();
  return Eigen::Vector3d(xy_base.x(), xy_base.y(), z);
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
