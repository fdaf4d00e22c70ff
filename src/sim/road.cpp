#include "ipm_road_mapper/sim/road.h"

#include <algorithm>
#include <cmath>

namespace ipm_road_mapper {
namespace sim {

RoadModel::RoadModel(const RoadOptions& options) : options_(options) {
  Piece piece;
  for (const auto& seg : options_.segments) {
    piece.length = seg.length_m;
    piece.curvature = seg.is_arc ? (seg.angle_deg > 0.0 ? 1.0 : -1.0) / seg.radius_m : 0.0;
    pieces_.push_back(piece);
    const CenterlinePoint end = PointOnPiece(piece, piece.length);
    piece.s0 += piece.length;
    piece.xy0 = end.xy;
    piece.heading0 = end.heading;
  }
  length_ = piece.s0;
  cross_slope_ = options_.surface.cross_slope_pct / 100.0;
  crown_ = options_.surface.crown_pct / 100.0;
  for (const auto& knot : options_.surface.grade) {
    const double grade = knot.grade_pct / 100.0;
    double z = 0.0;
    if (!knot_s_.empty()) {
      z = knot_z_.back() + 0.5 * (knot_grade_.back() + grade) * (knot.s_m - knot_s_.back());
    }
    knot_s_.push_back(knot.s_m);
    knot_grade_.push_back(grade);
    knot_z_.push_back(z);
  }
  if (!knot_s_.empty()) {
    const double z0 = GradeHeight(0.0);  // the road starts at z = 0
    for (double& z : knot_z_) z -= z0;
  }
}

CenterlinePoint RoadModel::PointOnPiece(const Piece& piece, double d) {
  CenterlinePoint p;
  p.heading = piece.heading0 + piece.curvature * d;
  p.curvature = piece.curvature;
  if (piece.curvature == 0.0) {
    p.xy = piece.xy0 + d * Eigen::Vector2d(std::cos(piece.heading0), std::sin(piece.heading0));
  } else {
    p.xy = piece.xy0 + Eigen::Vector2d(std::sin(p.heading) - std::sin(piece.heading0),
                                       std::cos(piece.heading0) - std::cos(p.heading)) /
                           piece.curvature;
  }
  return p;
}

CenterlinePoint RoadModel::Centerline(double s) const {
  if (s < 0.0 || s > length_) {
    // Outside the road: a straight continuation of the nearest end.
    const bool before = s < 0.0;
    CenterlinePoint p = before ? PointOnPiece(pieces_.front(), 0.0)
                               : PointOnPiece(pieces_.back(), pieces_.back().length);
    p.xy += (before ? s : s - length_) * p.Tangent();
    p.curvature = 0.0;
    return p;
  }
  std::size_t i = 0;
  while (i + 1 < pieces_.size() && s >= pieces_[i + 1].s0) ++i;
  return PointOnPiece(pieces_[i], s - pieces_[i].s0);
}

double RoadModel::GradeHeight(double s) const {
  if (knot_s_.empty()) return 0.0;
  const std::size_t n = knot_s_.size();
  if (s <= knot_s_[0]) return knot_z_[0] + knot_grade_[0] * (s - knot_s_[0]);
  if (s >= knot_s_[n - 1]) return knot_z_[n - 1] + knot_grade_[n - 1] * (s - knot_s_[n - 1]);
  const std::size_t i = std::upper_bound(knot_s_.begin(), knot_s_.end(), s) - knot_s_.begin() - 1;
  const double d = s - knot_s_[i];
  const double span = knot_s_[i + 1] - knot_s_[i];
  return knot_z_[i] + knot_grade_[i] * d +
         0.5 * (knot_grade_[i + 1] - knot_grade_[i]) / span * d * d;
}

double RoadModel::ProfileHeight(double s) const {
  double z = GradeHeight(s);
  for (const auto& w : options_.surface.waves) {
    z += w.amplitude_m * std::sin(2.0 * M_PI * s / w.wavelength_m + w.phase_deg * M_PI / 180.0);
  }
  for (const auto& b : options_.surface.bumps) {
    const double sigma = 0.25 * b.length_m;
    const double u = (s - b.s_m) / sigma;
    if (std::abs(u) < 8.0) z += b.height_m * std::exp(-0.5 * u * u);
  }
  return z;
}

Eigen::Vector3d RoadModel::SurfacePoint(double s, double l) const {
  const CenterlinePoint c = Centerline(s);
  const Eigen::Vector2d xy = c.xy + l * c.Normal();
  return {xy.x(), xy.y(), Height(s, l)};
}

Eigen::Vector2d RoadModel::Locate(const Eigen::Vector2d& xy, double s_hint) const {
  double s = s_hint, l = 0.0;
  for (int iteration = 0; iteration < 20; ++iteration) {
    const CenterlinePoint c = Centerline(s);
    const Eigen::Vector2d d = xy - c.xy;
    const double along = d.dot(c.Tangent());
    l = d.dot(c.Normal());
    s += along / std::max(0.2, 1.0 - c.curvature * l);
    if (std::abs(along) < 1e-10) break;
  }
  return {s, l};
}

double RoadModel::HeightAtXy(const Eigen::Vector2d& xy, double s_hint) const {
  const Eigen::Vector2d sl = Locate(xy, s_hint);
  return Height(sl.x(), sl.y());
}

double RoadModel::LineOffset(int line_index) const {
  return (line_index - 0.5 * options_.lanes) * options_.lane_width_m;
}

double RoadModel::LaneCenterOffset(int lane_index) const {
  return (lane_index + 0.5 - 0.5 * options_.lanes) * options_.lane_width_m;
}

SightProfile::SightProfile(const RoadModel& road, const Eigen::Vector3d& p_map_cam, double s_hint,
                           double range_m, double step_m)
    : road_(&road), step_(step_m) {
  const Eigen::Vector2d sl = road.Locate(p_map_cam.head<2>(), s_hint);
  s_cam_ = sl.x();
  l_cam_ = sl.y();
  z_cam_ = p_map_cam.z();
  const int n = static_cast<int>(std::ceil(range_m / step_)) + 2;
  profile_.resize(n);
  for (int i = 0; i < n; ++i) profile_[i] = road.ProfileHeight(s_cam_ + i * step_);
}

bool SightProfile::Visible(double s, double l, double z) const {
  const double span = s - s_cam_;
  if (span <= 0.5) return true;
  const int last =
      std::min(static_cast<int>((span - 0.3) / step_), static_cast<int>(profile_.size()) - 1);
  for (int i = 1; i <= last; ++i) {
    const double f = i * step_ / span;
    const double chord = z_cam_ + f * (z - z_cam_);
    if (chord < profile_[i] + road_->CrossHeight(l_cam_ + f * (l - l_cam_)) - 1e-4) return false;
  }
  return true;
}

}  // namespace sim
}  // namespace ipm_road_mapper
