#include "ipm_road_mapper/core/mapper/path_curvature.h"

#include <cmath>

namespace ipm_road_mapper {

namespace {
constexpr double kMaxChordSeconds = 20.0;  // slower than length_m per 20 s: no curvature read
}  // namespace

double PathCurvature(const std::vector<FrameRecord>& frames, std::size_t index, double length_m) {
  if (length_m <= 0.0 || index >= frames.size()) return 0.0;
  // The chord from the frame `length_m` back: per-frame position jitter (0.4 m at the
  // noisiest drive) would inflate a sum of steps.
  const Eigen::Vector2d p_now = frames[index].T_map_base.translation().head<2>();
  std::size_t k = index;
  double driven = 0.0;
  // Not past kMaxChordSeconds: at a standstill the chord never reaches length_m, and the walk
  // would go back through every frame of the stop (a cost growing with its length) to a
  // curve driven before it, which is not the path's curvature now.
  while (k > 0 && driven < length_m &&
         frames[index].stamp - frames[k - 1].stamp <= kMaxChordSeconds) {
    --k;
    driven = (p_now - frames[k].T_map_base.translation().head<2>()).norm();
  }
  if (driven < 0.5 * length_m) return 0.0;
  const Eigen::Vector3d x_now = frames[index].T_map_base.linear().col(0);
  const Eigen::Vector3d x_then = frames[k].T_map_base.linear().col(0);
  const double turn = std::atan2(x_then.x() * x_now.y() - x_then.y() * x_now.x(),
                                 x_then.x() * x_now.x() + x_then.y() * x_now.y());
  return turn / driven;
}

double ConcentricCurvature(const Eigen::Isometry3d& T_map_base, double path_curvature,
                           const Eigen::Vector3d& p_map, const Eigen::Vector3d& direction) {
  if (path_curvature == 0.0) return 0.0;
  const Eigen::Vector2d heading = T_map_base.linear().col(0).head<2>();
  const Eigen::Vector2d dir = direction.head<2>();
  if (dir.norm() < 1e-9 || heading.norm() < 1e-9) return 0.0;
  const double along = heading.dot(dir) / (heading.norm() * dir.norm());
  if (std::abs(along) < std::sqrt(0.5)) return 0.0;
  // The arc's center in base_link: 1 / kappa to the left (right for a right turn).
  const Eigen::Vector2d p_base = (T_map_base.inverse() * p_map).head<2>();
  const double radius = (p_base - Eigen::Vector2d(0.0, 1.0 / path_curvature)).norm();
  if (radius < 1e-6) return 0.0;
  return (along > 0.0 ? 1.0 : -1.0) * (path_curvature > 0.0 ? 1.0 : -1.0) / radius;
}

LaneEndCurvatures PathEndCurvatures(const std::vector<FrameRecord>& frames, std::size_t index,
                                    double length_m, double min_curvature,
                                    const std::vector<Eigen::Vector3d>& cps) {
  LaneEndCurvatures curvatures;
  const double path_curvature = PathCurvature(frames, index, length_m);
  if (path_curvature == 0.0 || cps.size() < 4) return curvatures;
  const Eigen::Isometry3d& T_map_base = frames[index].T_map_base;
  const std::size_t n = cps.size();
  curvatures.at_start = ConcentricCurvature(T_map_base, path_curvature, cps[1], cps[2] - cps[1]);
  curvatures.at_end =
      ConcentricCurvature(T_map_base, path_curvature, cps[n - 2], cps[n - 2] - cps[n - 3]);
  if (std::abs(curvatures.at_start) < min_curvature) curvatures.at_start = 0.0;
  if (std::abs(curvatures.at_end) < min_curvature) curvatures.at_end = 0.0;
  return curvatures;
}

double MinGrowthCurvature(double gate_m, double end_gap_m) {
  return end_gap_m > 0.0 ? 2.0 * gate_m / (end_gap_m * end_gap_m) : 0.0;
}

}  // namespace ipm_road_mapper
