// A road painted on the ground of a test camera: stripes (rotated rectangles on base_link's
// plane z = 0) rendered into a paint probability image, as a network would give it.
#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <opencv2/core.hpp>
#include <vector>

#include "common/test_scene.h"
#include "ipm_road_mapper/core/geometry/ipm.h"

namespace ipm_road_mapper {
namespace test {

// A painted rectangle on the ground: center, direction of its length, length, width (m).
struct Stripe {
  Eigen::Vector2d center;
  double angle_rad;
  double length_m;
  double width_m;

  bool Contains(const Eigen::Vector2d& p) const {
    const Eigen::Vector2d u(std::cos(angle_rad), std::sin(angle_rad)), v(-u.y(), u.x());
    return std::abs((p - center).dot(u)) <= 0.5 * length_m &&
           std::abs((p - center).dot(v)) <= 0.5 * width_m;
  }
};

// The camera of these tests: 1280x720, f = 1000 px, 1.5 m above base_link's origin,
// pitched 3 deg down.
inline PinholeCamera PaintCamera() { return PinholeCamera(Intrinsics1280x720()); }
inline Eigen::Isometry3d PaintMount() {
  return MountedCamera(0.0, 3.0 * M_PI / 180.0, 0.0, {0.0, 0.0, 1.5});
}

// Paint probability (CV_32F): 0.95 on the stripes, 0.02 elsewhere.
inline cv::Mat RenderPaint(const std::vector<Stripe>& stripes) {
  const PinholeCamera camera = PaintCamera();
  const Ipm ipm(camera, PaintMount(), 1e9);
  cv::Mat paint(camera.height(), camera.width(), CV_32F, cv::Scalar(0.02));
  for (int v = 0; v < camera.height(); ++v) {
    for (int u = 0; u < camera.width(); ++u) {
      Eigen::Vector3d p;
      if (ipm.PixelToGround(Eigen::Vector2d(u, v), &p) != IpmStatus::kOk) continue;
      for (const Stripe& s : stripes) {
        if (s.Contains(p.head<2>())) {
          paint.at<float>(v, u) = 0.95f;
          break;
        }
      }
    }
  }
  return paint;
}

// A solid line along x at lateral offset y (from x_from to x_to), 0.15 m wide.
inline Stripe SolidLine(double y, double x_from, double x_to) {
  return {{0.5 * (x_from + x_to), y}, 0.0, x_to - x_from, 0.15};
}

// Dashes of 3 m every 9 m along x at lateral offset y, from x_from.
inline std::vector<Stripe> DashedLine(double y, double x_from, int dashes) {
  std::vector<Stripe> out;
  for (int i = 0; i < dashes; ++i) out.push_back({{x_from + 1.5 + 9.0 * i, y}, 0.0, 3.0, 0.15});
  return out;
}

// Hatching: `count` stripes 0.4 m wide and 3 m long at `angle_rad`, their centers 1.5 m
// apart along x from (x_from, y).
inline std::vector<Stripe> Hatching(double x_from, double y, int count, double angle_rad) {
  std::vector<Stripe> out;
  for (int i = 0; i < count; ++i) out.push_back({{x_from + 1.5 * i, y}, angle_rad, 3.0, 0.4});
  return out;
}

}  // namespace test
}  // namespace ipm_road_mapper
