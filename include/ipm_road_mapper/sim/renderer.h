// Rasterization of 3D polygons into camera images for the synthetic drives: clipping
// against the view frustum in the camera frame (Sutherland-Hodgman, near plane first, so
// no point behind the camera is ever projected), densified projection through the
// distortion model, and sub-pixel polygon filling.
#pragma once

#include <Eigen/Core>
#include <array>
#include <opencv2/core.hpp>
#include <vector>

#include "ipm_road_mapper/core/geometry/pinhole_camera.h"
#include "ipm_road_mapper/sim/fill_rule.h"

namespace ipm_road_mapper {
namespace sim {

// Keeps the part of a polygon where plane.head<3>() . p + plane(3) >= 0 (one
// Sutherland-Hodgman pass; the result is empty or has >= 3 vertices).
std::vector<Eigen::Vector3d> ClipPolygon(const std::vector<Eigen::Vector3d>& polygon,
                                         const Eigen::Vector4d& plane);

// Clips camera-frame polygons to a frustum and projects them to pixels.
//
// The frustum is bounded by z >= near, z <= far (depth along the optical axis) and four
// side planes through the camera center a margin outside the image's undistorted field of
// view. The side planes matter as much as the near plane: plumb_bob distortion is a
// polynomial that folds back far outside the image (the wrap-around garbage), so the
// projector never evaluates it beyond the margin, where it is checked to be monotonic.
class FrustumProjector {
 public:
  // Edges are split until each projected piece is at most this long (px), so straight 3D
  // edges follow the distortion.
  static constexpr double kMaxEdgePx = 8.0;

  FrustumProjector(const PinholeCamera& camera, double near_m, double far_m);

  // Clipped, densified pixel polygon of a camera-frame polygon; empty when nothing of it is
  // inside the frustum.
  std::vector<Eigen::Vector2d> Project(const std::vector<Eigen::Vector3d>& polygon_cam) const;

  const PinholeCamera& camera() const { return camera_; }
  double near_m() const { return near_m_; }
  double far_m() const { return far_m_; }

 private:
  PinholeCamera camera_;
  double near_m_, far_m_;
  std::array<Eigen::Vector4d, 6> planes_;
};

// Fills a pixel polygon (pixel centers at integer coordinates) with `value` by `rule`.
// Returns the filled bounding box clipped to the image (empty when outside, or when a
// vertex is not finite).
cv::Rect FillPixelPolygon(const std::vector<Eigen::Vector2d>& uv, double value, cv::Mat* image,
                          FillRule rule = FillRule::kOpenCvFillPoly);

// A smooth random displacement field over the image (segmentation boundary jitter): two
// sinusoidal waves per axis with random directions and phases, amplitude `amplitude_px`
// overall and wavelength `wavelength_px`.
class JitterField {
 public:
  JitterField() = default;
  JitterField(double amplitude_px, double wavelength_px, const std::array<double, 8>& randoms);

  // The displaced pixel.
  Eigen::Vector2d Apply(const Eigen::Vector2d& uv) const;
  bool active() const { return amplitude_ > 0.0; }

 private:
  double amplitude_ = 0.0;
  std::array<Eigen::Vector2d, 4> k_;  // wave vectors (rad/px)
  std::array<double, 4> phase_{};
};

}  // namespace sim
}  // namespace ipm_road_mapper
