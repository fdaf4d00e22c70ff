// A raster of the ground ahead of the camera in base_link (x forward, y left), and the maps
// between it and the image: the paint of the image sampled onto the raster (the inverse
// perspective mapping of a whole mask at once), and each image pixel's raster cell.
#pragma once

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "ipm_road_mapper/core/geometry/pinhole_camera.h"

namespace ipm_road_mapper {
namespace segmentation {

// Extent and resolution of the raster (config section `raster`).
struct GroundRasterOptions {
  double cell_m = 0.05;      // side of a cell
  double min_ahead_m = 3.0;  // x range of base_link covered
  double max_ahead_m = 40.0;
  double half_width_m = 20.0;  // y in [-half_width_m, half_width_m]
};

// The raster for one camera and extrinsic. Row r holds x = max_ahead_m - (r + 0.5) * cell
// (far at the top, as in the image), column c holds y = half_width_m - (c + 0.5) * cell
// (left at the left). Rebuilt by the caller when the extrinsic changes (Matches).
class GroundRaster {
 public:
  GroundRaster(const PinholeCamera& camera, const Eigen::Isometry3d& T_base_cam,
               const GroundRasterOptions& options);

  // True when built for this camera and an extrinsic within `tolerance` (rotation rad,
  // translation m) of T_base_cam.
  bool Matches(const PinholeCamera& camera, const Eigen::Isometry3d& T_base_cam,
               double tolerance) const;

  int rows() const { return rows_; }
  int cols() const { return cols_; }
  double cell_m() const { return options_.cell_m; }
  const Eigen::Isometry3d& T_base_cam() const { return T_base_cam_; }

  // Center of cell (row, col) in base_link (x, y on the ground).
  Eigen::Vector2d CellCenter(int row, int col) const;
  // The cell holding ground point xy, false outside the raster.
  bool CellOf(const Eigen::Vector2d& xy_base, int* row, int* col) const;

  // An image-sized CV_8U or CV_32F image sampled at the cell centers (nearest pixel; 0 where
  // a cell is not in view).
  cv::Mat ToRaster(const cv::Mat& image) const;

  // Per image pixel, the index row * cols + col of its ground cell, -1 above the horizon or
  // outside the raster (CV_32S, image size).
  const cv::Mat& PixelCells() const { return pixel_cells_; }

 private:
  GroundRasterOptions options_;
  PinholeCamera camera_;
  Eigen::Isometry3d T_base_cam_;
  int rows_ = 0;
  int cols_ = 0;
  cv::Mat map_u_, map_v_;  // CV_32F, raster size: the pixel each cell samples
  cv::Mat pixel_cells_;
};

}  // namespace segmentation
}  // namespace ipm_road_mapper
