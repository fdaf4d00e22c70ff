#include "ipm_road_mapper/sim/renderer.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <vector>

namespace ipm_road_mapper {
namespace sim {
namespace {

constexpr int kFillShift = 4;  // cv::fillPoly fixed-point bits (1/16 px)

// d(r * radial(r)) / dr > 0 for r in [0, r_max]: the distortion does not fold back there.
bool RadialMonotonic(const CameraIntrinsics& in, double r_max) {
  const auto& d = in.distortion;
  for (int i = 1; i <= 200; ++i) {
    const double r2 = std::pow(r_max * i / 200.0, 2);
    if (1.0 + 3.0 * d[0] * r2 + 5.0 * d[1] * r2 * r2 + 7.0 * d[4] * r2 * r2 * r2 <= 0.05) {
      return false;
    }
  }
  return true;
}

cv::Rect FillWithOpenCv(const std::vector<Eigen::Vector2d>& uv, double value, cv::Mat* image) {
  std::vector<cv::Point> points;
  points.reserve(uv.size());
  const double scale = 1 << kFillShift;
  int u0 = INT32_MAX, v0 = INT32_MAX, u1 = INT32_MIN, v1 = INT32_MIN;
  for (const Eigen::Vector2d& p : uv) {
    points.emplace_back(static_cast<int>(std::lround(p.x() * scale)),
                        static_cast<int>(std::lround(p.y() * scale)));
    u0 = std::min(u0, static_cast<int>(std::floor(p.x())));
    v0 = std::min(v0, static_cast<int>(std::floor(p.y())));
    u1 = std::max(u1, static_cast<int>(std::ceil(p.x())));
    v1 = std::max(v1, static_cast<int>(std::ceil(p.y())));
  }
  const cv::Rect box =
      cv::Rect(u0, v0, u1 - u0 + 1, v1 - v0 + 1) & cv::Rect(0, 0, image->cols, image->rows);
  if (box.empty()) return {};
  const cv::Point* contour = points.data();
  const int count = static_cast<int>(points.size());
  cv::fillPoly(*image, &contour, &count, 1, cv::Scalar::all(value), cv::LINE_8, kFillShift);
  return box;
}

cv::Rect FillPixelCenters(const std::vector<Eigen::Vector2d>& uv, double value, cv::Mat* image) {
  double v_min = std::numeric_limits<double>::infinity(), v_max = -v_min;
  for (const Eigen::Vector2d& p : uv) {
    v_min = std::min(v_min, p.y());
    v_max = std::max(v_max, p.y());
  }
  // Rows whose centers lie within the polygon's extent, clipped to the image.
  const int row_begin = static_cast<int>(std::max(std::ceil(v_min), 0.0));
  const int row_end = static_cast<int>(std::min(std::floor(v_max), image->rows - 1.0));
  int u0 = INT32_MAX, v0 = INT32_MAX, u1 = INT32_MIN, v1 = INT32_MIN;
  std::vector<double> crossings;
  for (int v = row_begin; v <= row_end; ++v) {
    // Where the edges cross the row's center line; half-open in v so that a vertex on the
    // line counts once (even-odd rule).
    crossings.clear();
    for (std::size_t i = 0; i < uv.size(); ++i) {
      const Eigen::Vector2d& a = uv[i];
      const Eigen::Vector2d& b = uv[(i + 1) % uv.size()];
      if ((a.y() <= v && v < b.y()) || (b.y() <= v && v < a.y())) {
        crossings.push_back(a.x() + (v - a.y()) * (b.x() - a.x()) / (b.y() - a.y()));
      }
    }
    std::sort(crossings.begin(), crossings.end());
    for (std::size_t k = 0; k + 1 < crossings.size(); k += 2) {
      // Pixels whose centers u satisfy x0 <= u < x1, clipped to the image.
      const double first = std::max(std::ceil(crossings[k]), 0.0);
      const double last = std::min(std::ceil(crossings[k + 1]) - 1.0, image->cols - 1.0);
      if (first > last) continue;
      const int a = static_cast<int>(first), b = static_cast<int>(last);
      image->row(v).colRange(a, b + 1).setTo(cv::Scalar::all(value));
      u0 = std::min(u0, a);
      u1 = std::max(u1, b);
      v0 = std::min(v0, v);
      v1 = std::max(v1, v);
    }
  }
  if (u0 > u1) return {};
  return cv::Rect(u0, v0, u1 - u0 + 1, v1 - v0 + 1);
}

}  // namespace

std::vector<Eigen::Vector3d> ClipPolygon(const std::vector<Eigen::Vector3d>& polygon,
                                         const Eigen::Vector4d& plane) {
  std::vector<Eigen::Vector3d> out;
  const std::size_t n = polygon.size();
  if (n < 3) return out;
  out.reserve(n + 2);
  auto distance = [&](const Eigen::Vector3d& p) { return plane.head<3>().dot(p) + plane(3); };
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d& a = polygon[i];
    const Eigen::Vector3d& b = polygon[(i + 1) % n];
    const double da = distance(a), db = distance(b);
    if (da >= 0.0) out.push_back(a);
    if ((da >= 0.0) != (db >= 0.0)) out.push_back(a + (b - a) * (da / (da - db)));
  }
  if (out.size() < 3) out.clear();
  return out;
}

FrustumProjector::FrustumProjector(const PinholeCamera& camera, double near_m, double far_m)
    : camera_(camera), near_m_(near_m), far_m_(far_m) {
  // The undistorted field of view: normalized coordinates of the image border.
  double x_min = 1e9, x_max = -1e9, y_min = 1e9, y_max = -1e9;
  const int w = camera.width(), h = camera.height();
  for (int i = 0; i <= 64; ++i) {
    const double fu = (w - 1) * i / 64.0, fv = (h - 1) * i / 64.0;
    for (const Eigen::Vector2d& uv : {Eigen::Vector2d(fu, 0.0), Eigen::Vector2d(fu, h - 1.0),
                                      Eigen::Vector2d(0.0, fv), Eigen::Vector2d(w - 1.0, fv)}) {
      const Eigen::Vector2d xy = camera.UndistortToNormalized(uv);
      x_min = std::min(x_min, xy.x());
      x_max = std::max(x_max, xy.x());
      y_min = std::min(y_min, xy.y());
      y_max = std::max(y_max, xy.y());
    }
  }
  // A margin outside it, shrunk until the distortion is monotonic over the whole frustum.
  double margin = 0.15;
  double bx0, bx1, by0, by1;
  while (true) {
    const double mx = margin * (x_max - x_min), my = margin * (y_max - y_min);
    bx0 = x_min - mx, bx1 = x_max + mx, by0 = y_min - my, by1 = y_max + my;
    const double r_max = std::hypot(std::max(-bx0, bx1), std::max(-by0, by1));
    if (RadialMonotonic(camera.intrinsics(), r_max) || margin < 1e-3) break;
    margin *= 0.5;
  }
  planes_ = {Eigen::Vector4d(0.0, 0.0, 1.0, -near_m),  // near first: nothing behind the camera
             Eigen::Vector4d(0.0, 0.0, -1.0, far_m),  Eigen::Vector4d(1.0, 0.0, -bx0, 0.0),
             Eigen::Vector4d(-1.0, 0.0, bx1, 0.0),    Eigen::Vector4d(0.0, 1.0, -by0, 0.0),
             Eigen::Vector4d(0.0, -1.0, by1, 0.0)};
}

std::vector<Eigen::Vector2d> FrustumProjector::Project(
    const std::vector<Eigen::Vector3d>& polygon_cam) const {
  std::vector<Eigen::Vector3d> clipped = polygon_cam;
  for (const Eigen::Vector4d& plane : planes_) {
    clipped = ClipPolygon(clipped, plane);
    if (clipped.empty()) return {};
  }
  std::vector<Eigen::Vector2d> uv;
  const std::size_t n = clipped.size();
  std::vector<Eigen::Vector2d> corners(n);
  for (std::size_t i = 0; i < n; ++i) camera_.Project<double>(clipped[i], &corners[i]);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t j = (i + 1) % n;
    uv.push_back(corners[i]);
    const int pieces =
        std::min(256, static_cast<int>(std::ceil((corners[j] - corners[i]).norm() / kMaxEdgePx)));
    for (int k = 1; k < pieces; ++k) {
      Eigen::Vector2d p;
      camera_.Project<double>(clipped[i] + (clipped[j] - clipped[i]) * (double(k) / pieces), &p);
      uv.push_back(p);
    }
  }
  return uv;
}

cv::Rect FillPixelPolygon(const std::vector<Eigen::Vector2d>& uv, double value, cv::Mat* image,
                          FillRule rule) {
  if (uv.size() < 3 || image->empty()) return {};
  for (const Eigen::Vector2d& p : uv) {
    if (!p.allFinite()) return {};
  }
  return rule == FillRule::kPixelCenters ? FillPixelCenters(uv, value, image)
                                         : FillWithOpenCv(uv, value, image);
}

JitterField::JitterField(double amplitude_px, double wavelength_px,
                         const std::array<double, 8>& randoms)
    : amplitude_(amplitude_px) {
  const double k = 2.0 * M_PI / wavelength_px;
  for (int i = 0; i < 4; ++i) {
    const double angle = 2.0 * M_PI * randoms[2 * i];
    // Vary the wavelength a little per wave so the field is not periodic.
    const double ki = k * (0.7 + 0.6 * randoms[2 * i + 1]);
    k_[i] = ki * Eigen::Vector2d(std::cos(angle), std::sin(angle));
    phase_[i] = 2.0 * M_PI * std::fmod(randoms[2 * i] * 7.0 + randoms[2 * i + 1] * 13.0, 1.0);
  }
}

Eigen::Vector2d JitterField::Apply(const Eigen::Vector2d& uv) const {
  if (amplitude_ <= 0.0) return uv;
  // Each axis sums two unit waves; divide by sqrt(2) for an RMS displacement ~ amplitude/sqrt(2).
  const double du = std::sin(k_[0].dot(uv) + phase_[0]) + std::sin(k_[1].dot(uv) + phase_[1]);
  const double dv = std::sin(k_[2].dot(uv) + phase_[2]) + std::sin(k_[3].dot(uv) + phase_[3]);
  return uv + amplitude_ * M_SQRT1_2 * Eigen::Vector2d(du, dv);
}

}  // namespace sim
}  // namespace ipm_road_mapper
