// IPM uncertainty (the paper's Omega_p) and point selection (PS).
//
// The ground point of a pixel is p = f(uv, theta, h): the IPM of docs/design.md §4 with the camera
// pitched by theta about base_link's y axis (about the camera center) and raised by h.
// Three error sources propagate to first order:
//   Omega_p = J_uv e_p e_p^T J_uv^T + sigma_theta^2 J_theta J_theta^T + sigma_h^2 J_h J_h^T
// with J_uv = df/duv (3x2), J_theta = df/dtheta, J_h = df/dh (3x1) at theta = h = 0, and
// e_p the pixel error *vector* (the paper models it as a vector, not per-axis sigmas).
// The score is tr(Omega_p) (m^2); PS keeps the N points with the lowest score. The
// Jacobians are autodiffed through Ipm::GroundPoint, the same function the mapper uses.
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <optional>
#include <vector>

#include "ipm_road_mapper/core/geometry/pinhole_camera.h"

namespace ipm_road_mapper {

// Error model of one IPM measurement (docs/design.md §4 defaults: 2 px, 0.3 deg, 0.05 m).
struct IpmErrorModel {
  Eigen::Vector2d pixel_error_px{2.0, 2.0};     // e_p, the segmentation error vector (u, v)
  double pitch_sigma_rad = 0.3 * M_PI / 180.0;  // sigma_theta: camera pitch vs the road
  double height_sigma_m = 0.05;                 // sigma_h: camera height above the road
};

// Omega_p of one pixel with the Jacobians it is built from.
struct IpmUncertainty {
  Eigen::Vector3d p_base = Eigen::Vector3d::Zero();  // the ground point itself
  Eigen::Matrix<double, 3, 2> J_uv = Eigen::Matrix<double, 3, 2>::Zero();
  Eigen::Vector3d J_theta = Eigen::Vector3d::Zero();
  Eigen::Vector3d J_h = Eigen::Vector3d::Zero();
  Eigen::Matrix3d omega = Eigen::Matrix3d::Zero();  // Omega_p (m^2)
  double score = 0.0;                               // tr(Omega_p) (m^2)
};

// Omega_p for pixel uv; empty when the pixel is at or above the horizon.
std::optional<IpmUncertainty> ComputeIpmUncertainty(const PinholeCamera& camera,
                                                    const Eigen::Isometry3d& T_base_cam,
                                                    const Eigen::Vector2d& uv,
                                                    const IpmErrorModel& model);

// The ground point f(uv, theta, h) in double, the function the Jacobians differentiate
// (exposed for tests). False when the ray does not descend.
bool PerturbedGroundPoint(const PinholeCamera& camera, const Eigen::Isometry3d& T_base_cam,
                          const Eigen::Vector2d& uv, double theta, double h,
                          Eigen::Vector3d* p_base);

// Point selection tau(P): indices of the n lowest scores, ascending by score (ties keep
// input order); all indices when n >= scores.size(). Non-finite scores are never selected.
std::vector<std::size_t> SelectLowestScores(const std::vector<double>& scores, std::size_t n);

}  // namespace ipm_road_mapper
