#include "ipm_road_mapper/segmentation/ground_raster.h"

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "ipm_road_mapper/core/geometry/ipm.h"

namespace ipm_road_mapper {
namespace segmentation {

GroundRaster::GroundRaster(const PinholeCamera& camera, const Eigen::Isometry3d& T_base_cam,
                           const GroundRasterOptions& options)
    : options_(options), camera_(camera), T_base_cam_(T_base_cam) {
  rows_ = std::max(
      1, static_cast<int>(std::ceil((options.max_ahead_m - options.min_ahead_m) / options.cell_m)));
  cols_ = std::max(1, static_cast<int>(std::ceil(2.0 * options.half_width_m / options.cell_m)));
  // No range limit: the raster's extent is the limit.
  const Ipm ipm(camera, T_base_cam, 1e9);
  map_u_.create(rows_, cols_, CV_32F);
  map_v_.create(rows_, cols_, CV_32F);
  for (int r = 0; r < rows_; ++r) {
    for (int c = 0; c < cols_; ++c) {
      const Eigen::Vector2d xy = CellCenter(r, c);
      Eigen::Vector2d uv;
      const bool seen = ipm.BaseToPixel(Eigen::Vector3d(xy.x(), xy.y(), 0.0), &uv);
      map_u_.at<float>(r, c) = seen ? static_cast<float>(uv.x()) : -1.0f;
      map_v_.at<float>(r, c) = seen ? static_cast<float>(uv.y()) : -1.0f;
    }
  }
  pixel_cells_.create(camera.height(), camera.width(), CV_32S);
  for (int v = 0; v < camera.height(); ++v) {
    int* row_cells = pixel_cells_.ptr<int>(v);
    for (int u = 0; u < camera.width(); ++u) {
      Eigen::Vector3d p_base;
      int r = -1, c = -1;
      const bool ok = ipm.PixelToGround(Eigen::Vector2d(u, v), &p_base) == IpmStatus::kOk &&
                      CellOf(p_base.head<2>(), &r, &c);
      row_cells[u] = ok ? r * cols_ + c : -1;
    }
  }
}

bool GroundRaster::Matches(const PinholeCamera& camera, const Eigen::Isometry3d& T_base_cam,
                           double tolerance) const {
  const CameraIntrinsics& a = camera.intrinsics();
  const CameraIntrinsics& b = camera_.intrinsics();
  if (a.width != b.width || a.height != b.height || a.fx != b.fx || a.fy != b.fy || a.cx != b.cx ||
      a.cy != b.cy || a.distortion != b.distortion) {
    return false;
  }
  const Eigen::AngleAxisd delta(T_base_cam_.linear().transpose() * T_base_cam.linear());
  return std::abs(delta.angle()) <= tolerance &&
         (T_base_cam_.translation() - T_base_cam.translation()).norm() <= tolerance;
}

Eigen::Vector2d GroundRaster::CellCenter(int row, int col) const {
  return {options_.max_ahead_m - (row + 0.5) * options_.cell_m,
          options_.half_width_m - (col + 0.5) * options_.cell_m};
}

bool GroundRaster::CellOf(const Eigen::Vector2d& xy_base, int* row, int* col) const {
  const double r = (options_.max_ahead_m - xy_base.x()) / options_.cell_m;
  const double c = (options_.half_width_m - xy_base.y()) / options_.cell_m;
  if (!(r >= 0.0 && c >= 0.0 && r < rows_ && c < cols_)) return false;
  *row = static_cast<int>(r);
  *col = static_cast<int>(c);
  return true;
}

cv::Mat GroundRaster::ToRaster(const cv::Mat& image) const {
  cv::Mat raster;
  cv::remap(image, raster, map_u_, map_v_, cv::INTER_NEAREST, cv::BORDER_CONSTANT, 0);
  return raster;
}

}  // namespace segmentation
}  // namespace ipm_road_mapper
