#include "ipm_road_mapper/core/geometry/lane_end_line.h"

#include <Eigen/Dense>
#include <cmath>

namespace ipm_road_mapper {

LaneEndLine FitLaneEndLine(const std::vector<Eigen::Vector3d>& control_points, bool at_end,
                           double length_m) {
  LaneEndLine line;
  const std::size_t n = control_points.size();
  if (n < 4) return line;
  const std::size_t real = n - 2;
  // The k-th real control point from the end inward.
  auto real_point = [&](std::size_t k) -> Eigen::Vector2d {
    return control_points[at_end ? n - 2 - k : 1 + k].head<2>();
  };
  const Eigen::Vector2d end = real_point(0);
  if (!end.allFinite()) return line;
  std::vector<Eigen::Vector2d> samples{end};
  for (std::size_t k = 1; k < real; ++k) {
    const Eigen::Vector2d c = real_point(k);
    if (!c.allFinite()) return line;
    if (samples.size() >= 2 && (c - end).norm() > length_m) break;
    samples.push_back(c);
  }
  if (samples.size() < 2) return line;
  const Eigen::Vector2d chord = end - samples.back();
  if (chord.norm() < 1e-6) return line;
  line.origin = end;
  line.forward = chord.normalized();
  line.left = Eigen::Vector2d(-line.forward.y(), line.forward.x());
  // min sum_i (l_i - a - b s_i)^2: the 2x2 normal equations (the s_i are distinct along the
  // chord's direction unless the lane doubles back, which the solve's check catches).
  Eigen::Matrix2d A = Eigen::Matrix2d::Zero();
  Eigen::Vector2d rhs = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d& c : samples) {
    const Eigen::Vector2d row(1.0, (c - end).dot(line.forward));
    A += row * row.transpose();
    rhs += row * (c - end).dot(line.left);
  }
  const Eigen::Vector2d ab = A.ldlt().solve(rhs);
  if (!ab.allFinite() || !(std::abs(A.determinant()) > 1e-9)) return line;
  line.offset_m = ab(0);
  line.slope = ab(1);
  line.valid = true;
  return line;
}

double DistanceFromEndLine(const LaneEndLine& line, const Eigen::Vector3d& p_map, double* along_m) {
  const Eigen::Vector2d d = p_map.head<2>() - line.origin;
  const double s = d.dot(line.forward), l = d.dot(line.left);
  if (along_m) *along_m = s;
  // The offset from the line measured across `forward`, times the cosine of its angle.
  return std::abs(l - line.offset_m - line.slope * s) / std::sqrt(1.0 + line.slope * line.slope);
}

}  // namespace ipm_road_mapper
