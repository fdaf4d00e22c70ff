// Marginalization of retired map points into the extrinsic prior (extrinsic_prior.h).
//
// When a marking has left the window for good, its measurements still say something about
// the extrinsic. With x = [p ; delta] (the points and the
// extrinsic's tangent), the measurements' Gauss-Newton cost around the current estimate is
//   1/2 dx^T H dx + g^T dx,   H = J^T W J,  g = J^T W r   (W: Huber weights at r)
// and minimizing over the points leaves the Schur complement on delta:
//   H_d = H_ee - H_ep H_pp^-1 H_pe,   g_d = g_e - H_ep H_pp^-1 g_p.
// The frames' poses are data (they are out of the window too). The Jacobians with respect
// to delta are autodiffed through the same residual functions the window uses, with the
// extrinsic written in the prior's chart: q = Exp(delta_rot) q0, t = t0 + delta_t.
#pragma once

#include <Eigen/Geometry>
#include <vector>

#include "ipm_road_mapper/core/backend/extrinsic_prior.h"
#include "ipm_road_mapper/core/geometry/pinhole_camera.h"
#include "ipm_road_mapper/core/geometry/road_surface.h"

namespace ipm_road_mapper {

// The retired measurements of some map points (indices into MarginalizationInput::points):
// the corners of markings.
struct MarginalizationInput {
  std::vector<Eigen::Vector3d> points;  // current estimates (map frame)
  struct Corner {
    int point = 0;
    Eigen::Vector2d uv;
    Eigen::Isometry3d T_map_base;
    // Whitening of the pixel error (pose_uncertainty.h); zero: I / pixel_sigma_px.
    Eigen::Matrix2d sqrt_information = Eigen::Matrix2d::Zero();
  };
  struct RoadPrior {  // the point lies on the road's plane (road_surface_prior_residual.h)
    int point = 0;
    RoadPlane plane;
    double sigma_m = 0.1;
  };
  std::vector<Corner> corners;
  std::vector<RoadPrior> road_priors;
};

// The factor on the extrinsic's delta (in `chart`'s coordinates) of the input's
// measurements, its points marginalized, linearized at T_base_cam and the points' values.
// A point no measurement reaches contributes nothing; an empty input gives a zero factor.
ExtrinsicFactor MarginalizeIntoExtrinsic(const PinholeCamera& camera, const ExtrinsicPrior& chart,
                                         const Eigen::Isometry3d& T_base_cam,
                                         const MarginalizationInput& input, double pixel_sigma_px,
                                         double huber_scale);

}  // namespace ipm_road_mapper
