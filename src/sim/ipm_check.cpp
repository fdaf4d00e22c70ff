#include "ipm_road_mapper/sim/ipm_check.h"

#include <cmath>
#include <limits>

#include "ipm_road_mapper/core/geometry/ipm.h"

namespace ipm_road_mapper {
namespace sim {
namespace {

// Mean and (population) standard deviation of the finite values.
void MeanStd(const std::vector<double>& values, double* mean, double* std) {
  double sum = 0.0, sum2 = 0.0;
  int n = 0;
  for (double v : values) {
    if (!std::isfinite(v)) continue;
    sum += v;
    sum2 += v * v;
    ++n;
  }
  *mean = n > 0 ? sum / n : 0.0;
  *std = n > 0 ? std::sqrt(std::max(0.0, sum2 / n - *mean * *mean)) : 0.0;
}

}  // namespace

PlainIpmError ComputePlainIpmError(const GroundTruth& gt, double max_distance_m) {
  PlainIpmError result;
  const PinholeCamera camera(gt.camera);
  const Ipm rough_ipm(camera, gt.T_base_cam_rough, std::numeric_limits<double>::infinity());
  std::vector<Eigen::Isometry3d> T_cam_map(gt.frames.size());
  for (std::size_t k = 0; k < gt.frames.size(); ++k) {
    T_cam_map[k] = (gt.frames[k].T_map_base_true * gt.T_base_cam_true).inverse();
  }
  std::vector<double> xy_errors;
  for (const GroundTruthMarking& marking : gt.markings) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    int frames = 0;
    for (std::size_t k = 0; k < gt.frames.size(); ++k) {
      Eigen::Vector3d center = Eigen::Vector3d::Zero();
      bool ok = true;
      for (const Eigen::Vector3d& corner_map : marking.corners_map) {
        const Eigen::Vector3d p_cam = T_cam_map[k] * corner_map;
        Eigen::Vector2d uv;
        Eigen::Vector3d p_base;
        ok = p_cam.norm() <= max_distance_m && camera.Project<double>(p_cam, &uv) &&
             camera.InImage(uv) && rough_ipm.PixelToGround(uv, &p_base) == IpmStatus::kOk;
        if (!ok) break;
        center += 0.25 * (gt.frames[k].T_map_base_odom * p_base);
      }
      if (!ok) continue;
      sum += center;
      ++frames;
    }
    double error = std::numeric_limits<double>::quiet_NaN();
    double error_xy = error;
    if (frames > 0) {
      const Eigen::Vector3d delta = sum / frames - marking.center_map;
      error = delta.norm();
      error_xy = delta.head<2>().norm();
      ++result.markings;
      result.observations += frames;
      result.max_m = std::max(result.max_m, error);
    }
    result.per_marking_m.push_back(error);
    xy_errors.push_back(error_xy);
  }
  MeanStd(result.per_marking_m, &result.mean_m, &result.std_m);
  MeanStd(xy_errors, &result.mean_xy_m, &result.std_xy_m);
  return result;
}

}  // namespace sim
}  // namespace ipm_road_mapper
