#include "ipm_road_mapper/core/geometry/trajectory_road_plane.h"

#include <cmath>
#include <limits>

namespace ipm_road_mapper {
namespace {

// A quadratic needs this many heights.
constexpr std::size_t kMinQuadraticPoints = 6;

// The slope dz/ds at the newest pose of the heights of the poses within grade_length_m of path
// behind it, s the horizontal distance travelled back along the path (negative); NaN when the
// path there is shorter than kMinGradePathM. Heights are taken relative to the newest's, so
// that equal heights give a slope of exactly 0.
double PathGrade(const std::vector<StampedPose>& recent, double grade_length_m) {
  const Eigen::Vector3d newest = recent.back().T_map_base.translation();
  std::vector<Eigen::Vector2d> s_dz;  // (s, z - z_newest)
  s_dz.emplace_back(0.0, 0.0);
  double s = 0.0;
  for (std::size_t i = recent.size() - 1; i > 0; --i) {
    const Eigen::Vector3d a = recent[i].T_map_base.translation();
    const Eigen::Vector3d b = recent[i - 1].T_map_base.translation();
    s -= (a - b).head<2>().norm();
    if (-s > grade_length_m) break;
    s_dz.emplace_back(s, b.z() - newest.z());
  }
  if (-s_dz.back().x() < kMinGradePathM) return std::numeric_limits<double>::quiet_NaN();
  // z = a + b s + c s^2 by least squares where the path spans half the length or more (a
  // grade that changes, a crest: the slope at s = 0, not the chord's lagging one), else a
  // line; the slope at the newest pose is b.
  const bool quadratic =
      -s_dz.back().x() >= 0.5 * grade_length_m && s_dz.size() >= kMinQuadraticPoints;
  const int terms = quadratic ? 3 : 2;
  Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
  Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
  for (const Eigen::Vector2d& p : s_dz) {
    const Eigen::Vector3d basis(1.0, p.x(), quadratic ? p.x() * p.x() : 0.0);
    normal += basis * basis.transpose();
    rhs += basis * p.y();
  }
  const Eigen::VectorXd coefficients =
      normal.topLeftCorner(terms, terms).ldlt().solve(rhs.head(terms));
  return coefficients(1);
}

// The mean of base_link's z axis (in the map) over the poses within window_s of the newest.
Eigen::Vector3d MeanBodyNormal(const std::vector<StampedPose>& recent, double window_s) {
  const double newest_stamp = recent.back().stamp;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int count = 0;
  for (std::size_t i = recent.size(); i > 0; --i) {
    const StampedPose& pose = recent[i - 1];
    if (count > 0 && newest_stamp - pose.stamp > window_s) break;
    sum += pose.T_map_base.linear().col(2);
    ++count;
  }
  return sum / static_cast<double>(count);
}

}  // namespace

RoadPlane RoadPlaneFromTrajectory(const std::vector<StampedPose>& recent,
                                  const TrajectoryRoadPlaneOptions& options) {
  RoadPlane plane;  // base_link's z = 0
  if (recent.empty()) return plane;
  const Eigen::Matrix3d& R_map_base = recent.back().T_map_base.linear();
  Eigen::Vector3d normal_map = MeanBodyNormal(recent, options.cross_slope_window_s);
  const double grade = PathGrade(recent, options.grade_length_m);
  const Eigen::Vector3d heading(R_map_base(0, 0), R_map_base(1, 0), 0.0);
  if (std::isfinite(grade) && heading.norm() > 1e-6) {
    // The road's direction along the path, and the mean normal with its component along
    // that direction (the body's mean pitch) removed: what is left is the cross slope.
    const Eigen::Vector3d along =
        (heading.normalized() + grade * Eigen::Vector3d::UnitZ()).normalized();
    normal_map -= normal_map.dot(along) * along;
  }
  if (!(normal_map.norm() > 0.0)) return plane;
  plane.normal = R_map_base.transpose() * normal_map.normalized();
  if (plane.normal.z() < 0.0) plane.normal = -plane.normal;
  return plane;
}

}  // namespace ipm_road_mapper
