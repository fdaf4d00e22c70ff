// Test helpers: a forward-looking test camera and synthetic 16UC1 instance masks rendered
// from ground polygons of base_link (z = 0).
//
// Rendering samples pixel centers: pixel (col, row) gets the value when its center
// uv = (col, row) lies inside the projected polygon, the 50%-coverage rule a segmentation
// network approximates. (cv::fillPoly rounds vertices to pixel centers and fills both end
// pixels of every span, which inflates shapes by about half a pixel per side.)
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "common/test_scene.h"
#include "ipm_road_mapper/core/geometry/ipm.h"
#include "ipm_road_mapper/core/geometry/pinhole_camera.h"

namespace ipm_road_mapper {
namespace test {

constexpr int kTestWidth = 1280;
constexpr int kTestHeight = 720;

// 1280x720, fx = fy = 1000, principal point at the image center, no distortion.
inline PinholeCamera TestCamera() {
  return PinholeCamera(Intrinsics(kTestWidth, kTestHeight, 1000.0, 640.0, 360.0));
}

// Camera `height_m` above base_link's origin looking forward, pitched down by `pitch_deg`.
// The optical frame's z maps to base x, its x to -base y and its y to -base z; the pitch
// then turns the optical axis about base y (positive: nose down).
inline Eigen::Isometry3d TestTBaseCam(double pitch_deg = 5.0, double height_m = 1.5) {
  Eigen::Matrix3d R_base_opt;
  R_base_opt.col(0) = Eigen::Vector3d(0.0, -1.0, 0.0);  // optical x -> -base y
  R_base_opt.col(1) = Eigen::Vector3d(0.0, 0.0, -1.0);  // optical y -> -base z
  R_base_opt.col(2) = Eigen::Vector3d(1.0, 0.0, 0.0);   // optical z -> base x
  const Eigen::Matrix3d R_pitch =
      Eigen::AngleAxisd(pitch_deg * M_PI / 180.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
  Eigen::Isometry3d T_base_cam = Eigen::Isometry3d::Identity();
  T_base_cam.linear() = R_pitch * R_base_opt;
  T_base_cam.translation() = Eigen::Vector3d(0.0, 0.0, height_m);
  return T_base_cam;
}

// The test Ipm: TestCamera at TestTBaseCam, max range 50 m.
inline Ipm TestIpm(double max_range_m = 50.0) {
  return Ipm(TestCamera(), TestTBaseCam(), max_range_m);
}

// An empty (all background) test mask.
inline cv::Mat EmptyMask() { return cv::Mat(kTestHeight, kTestWidth, CV_16UC1, cv::Scalar(0)); }

// Corners (counter-clockwise seen from above) of a ground rectangle centered at
// center_base, `length_m` along the direction yaw_rad (from base x towards base y) and
// `width_m` across it.
inline std::vector<Eigen::Vector2d> GroundRectangle(const Eigen::Vector2d& center_base,
                                                    double length_m, double width_m,
                                                    double yaw_rad) {
  const Eigen::Vector2d along(std::cos(yaw_rad), std::sin(yaw_rad));
  const Eigen::Vector2d across(-along.y(), along.x());
  const Eigen::Vector2d a = 0.5 * length_m * along, b = 0.5 * width_m * across;
  return {center_base - a - b, center_base + a - b, center_base + a + b, center_base - a + b};
}

// Fills, with `value`, every pixel whose center lies inside the image polygon `uv`
// (even-odd rule, scanline at each row's center).
inline void FillPolygonCenters(const std::vector<Eigen::Vector2d>& uv, std::uint16_t value,
                               cv::Mat* mask) {
  double min_v = uv[0].y(), max_v = uv[0].y();
  for (const Eigen::Vector2d& p : uv) {
    min_v = std::min(min_v, p.y());
    max_v = std::max(max_v, p.y());
  }
  const int first_row = std::max(0, static_cast<int>(std::ceil(min_v)));
  const int last_row = std::min(mask->rows - 1, static_cast<int>(std::floor(max_v)));
  std::vector<double> crossings;
  for (int row = first_row; row <= last_row; ++row) {
    crossings.clear();
    for (std::size_t i = 0; i < uv.size(); ++i) {
      const Eigen::Vector2d& a = uv[i];
      const Eigen::Vector2d& b = uv[(i + 1) % uv.size()];
      if ((a.y() > row) == (b.y() > row)) continue;
      crossings.push_back(a.x() + (row - a.y()) * (b.x() - a.x()) / (b.y() - a.y()));
    }
    std::sort(crossings.begin(), crossings.end());
    std::uint16_t* pixels = mask->ptr<std::uint16_t>(row);
    for (std::size_t k = 0; k + 1 < crossings.size(); k += 2) {
      const int first_col = std::max(0, static_cast<int>(std::ceil(crossings[k])));
      const int last_col = std::min(mask->cols - 1, static_cast<int>(std::floor(crossings[k + 1])));
      for (int col = first_col; col <= last_col; ++col) pixels[col] = value;
    }
  }
}

// Renders a ground polygon (base_link, z = 0, entirely in front of the camera) into the
// mask: its edges densified every `step_m` (straight on the ground, curved in a distorted
// image), projected with Ipm::BaseToPixel, filled by pixel centers.
inline void RenderGroundPolygon(const Ipm& ipm, const std::vector<Eigen::Vector2d>& polygon_base,
                                std::uint16_t value, cv::Mat* mask, double step_m = 0.1) {
  std::vector<Eigen::Vector2d> uv;
  for (std::size_t i = 0; i < polygon_base.size(); ++i) {
    const Eigen::Vector2d& a = polygon_base[i];
    const Eigen::Vector2d& b = polygon_base[(i + 1) % polygon_base.size()];
    const int steps = std::max(1, static_cast<int>(std::ceil((b - a).norm() / step_m)));
    for (int k = 0; k < steps; ++k) {
      const Eigen::Vector2d p = a + (b - a) * (static_cast<double>(k) / steps);
      Eigen::Vector2d pixel;
      if (ipm.BaseToPixel(Eigen::Vector3d(p.x(), p.y(), 0.0), &pixel)) uv.push_back(pixel);
    }
  }
  if (uv.size() >= 3) FillPolygonCenters(uv, value, mask);
}

// Renders a ground rectangle (see GroundRectangle).
inline void RenderGroundRectangle(const Ipm& ipm, const Eigen::Vector2d& center_base,
                                  double length_m, double width_m, double yaw_rad,
                                  std::uint16_t value, cv::Mat* mask) {
  RenderGroundPolygon(ipm, GroundRectangle(center_base, length_m, width_m, yaw_rad), value, mask);
}

// Renders a straight lane strip along base x from x_from_m to x_to_m at lateral offset y_m.
inline void RenderLaneStrip(const Ipm& ipm, double y_m, double x_from_m, double x_to_m,
                            double width_m, std::uint16_t value, cv::Mat* mask) {
  RenderGroundRectangle(ipm, Eigen::Vector2d(0.5 * (x_from_m + x_to_m), y_m), x_to_m - x_from_m,
                        width_m, 0.0, value, mask);
}

}  // namespace test
}  // namespace ipm_road_mapper
