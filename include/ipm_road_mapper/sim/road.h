// Road model of a synthetic drive: a horizontal centerline of straights and circular arcs
// parameterized by arc length s, and a non-planar surface height z(s, l) over it (l is the
// lateral offset, left > 0). Frames follow docs/design.md §2: map z up.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <vector>

#include "ipm_road_mapper/sim/scenario.h"

namespace ipm_road_mapper {
namespace sim {

// The centerline at one s: position, heading (rad, from map x) and signed curvature.
struct CenterlinePoint {
  Eigen::Vector2d xy = Eigen::Vector2d::Zero();
  double heading = 0.0;
  double curvature = 0.0;  // 1/m, > 0 turning left
  Eigen::Vector2d Tangent() const { return {std::cos(heading), std::sin(heading)}; }
  Eigen::Vector2d Normal() const { return {-std::sin(heading), std::cos(heading)}; }
};

// Centerline and surface. The centerline starts at the map origin heading along +x; s is
// measured horizontally. Outside [0, length] it continues straight along the end tangents
// and the grade stays constant, so any s can be evaluated.
class RoadModel {
 public:
  explicit RoadModel(const RoadOptions& options);

  double length() const { return length_; }
  const RoadOptions& options() const { return options_; }

  // Centerline position, heading and curvature at s.
  CenterlinePoint Centerline(double s) const;

  // Surface height at (s, l): z_grade(s) + CrossHeight(l) + waves(s) + bumps(s).
  double Height(double s, double l) const { return ProfileHeight(s) + CrossHeight(l); }

  // The part of the height that depends on l only: cross_slope * l - crown * |l - l_crown|.
  double CrossHeight(double l) const {
    return cross_slope_ * l - crown_ * std::abs(l - options_.surface.crown_offset_m);
  }

  // The part of the height that depends on s only (grade, waves, bumps).
  double ProfileHeight(double s) const;

  // Cross slope dz/dl (m/m) without the crown; the crown's fall (m/m, >= 0).
  double cross_slope() const { return cross_slope_; }
  double crown() const { return crown_; }

  // The 3D surface point at (s, l) in the map frame.
  Eigen::Vector3d SurfacePoint(double s, double l) const;

  // Horizontal map point -> (s, l) by projection onto the centerline, starting from
  // `s_hint` (must be within a few tens of meters of the answer).
  Eigen::Vector2d Locate(const Eigen::Vector2d& xy, double s_hint) const;

  // Surface height under a horizontal map point (see Locate for the hint).
  double HeightAtXy(const Eigen::Vector2d& xy, double s_hint) const;

  // Lateral offset of lane line i (0 = rightmost line, lanes = leftmost).
  double LineOffset(int line_index) const;

  // Lateral offset of the center of lane k (0 = rightmost lane).
  double LaneCenterOffset(int lane_index) const;

 private:
  // One piece of the centerline.
  struct Piece {
    double s0 = 0.0, length = 0.0, curvature = 0.0;
    Eigen::Vector2d xy0 = Eigen::Vector2d::Zero();
    double heading0 = 0.0;
  };

  // The centerline `d` meters into a piece.
  static CenterlinePoint PointOnPiece(const Piece& piece, double d);
  // Height of the grade profile alone (0 at s = 0).
  double GradeHeight(double s) const;

  RoadOptions options_;
  std::vector<Piece> pieces_;
  double length_ = 0.0;
  double cross_slope_ = 0.0;
  double crown_ = 0.0;
  std::vector<double> knot_s_, knot_grade_, knot_z_;  // grade as a fraction
};

// Visibility of surface points from a camera over the road's own relief. The line of sight
// from the camera to a point is tested against the surface along s: its lateral offset l is
// linear in s on a straight road, so at each profile sample the sight line's height is
// compared with ProfileHeight(s) + CrossHeight(l) there, which is exact on straight roads
// (a ridge the sight line crosses can hide what lies beyond it); on arcs the lateral path
// of the sight line is approximated linearly in s (a few cm for radii >= 100 m within 40 m).
class SightProfile {
 public:
  SightProfile() = default;  // sees everything
  // Samples the profile from the camera's s to s + range_m every `step_m`. Keeps a pointer to
  // `road` (its cross-section, RoadModel::CrossHeight): the road must outlive the profile.
  SightProfile(const RoadModel& road, const Eigen::Vector3d& p_map_cam, double s_hint,
               double range_m, double step_m = 0.25);

  // True when the point at (s, l, z) on or above the surface is not hidden by the road.
  bool Visible(double s, double l, double z) const;

 private:
  const RoadModel* road_ = nullptr;
  double s_cam_ = 0.0, l_cam_ = 0.0, z_cam_ = 0.0, step_ = 0.25;
  std::vector<double> profile_;  // ProfileHeight at s_cam_ + i * step_
};

}  // namespace sim
}  // namespace ipm_road_mapper
