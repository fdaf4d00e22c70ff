// Paint on the ground raster split into pieces of one direction each: a dash, a stripe of a
// hatched area, a stretch of a solid line, split from the paint it touches (a chevron
// merged with the edge line it starts on) where the paint's direction turns.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <vector>

#include "ipm_road_mapper/segmentation/ground_raster.h"

namespace ipm_road_mapper {
namespace segmentation {

// How paint is split (config section `pieces`).
struct PieceOptions {
  double orientation_scale_m = 0.3;  // window of the structure tensor (Gaussian sigma)
  double min_coherence = 0.35;       // below: a cell has no direction (a blob's inside)
  double max_turn_deg = 25.0;        // neighbouring cells turning more are split apart
  double min_area_m2 = 0.03;         // smaller pieces are speckle (dropped, counted)
  double blob_core_radius_m = 0.4;   // paint this far from any edge is a blob's core
};

// One piece, measured on the ground (base_link x, y).
struct PaintPiece {
  std::vector<int> cells;  // raster cell indices (row * cols + col)
  Eigen::Vector2d center = Eigen::Vector2d::Zero();
  Eigen::Vector2d direction = Eigen::Vector2d::UnitX();  // unit, the principal axis
  double length_m = 0.0;                                 // extent along direction
  double width_m = 0.0;                                  // area / length: the mean width
  double area_m2 = 0.0;
  double coherence = 0.0;          // mean coherence of its cells (1: a clean stroke)
  double paint_probability = 1.0;  // mean paint probability of its cells
  bool touches_edge = false;       // reaches the edge of the view (cut, not whole)

  // Ends along `direction`: center -/+ length / 2 * direction.
  Eigen::Vector2d Start() const { return center - 0.5 * length_m * direction; }
  Eigen::Vector2d End() const { return center + 0.5 * length_m * direction; }
};

// The split's result: the pieces, and the cells dropped as speckle.
struct PieceSplit {
  std::vector<PaintPiece> pieces;
  int speckle_pieces = 0;
};

// Splits the paint of `paint` (CV_8U raster, nonzero = paint) into pieces: the direction of
// each cell from the structure tensor of the paint, then 8-connected cells joined when both
// have a direction within max_turn_deg of each other, or neither has one. `probability`
// (CV_32F raster, may be empty) gives each piece its mean paint probability; `in_view`
// (CV_8U raster, nonzero where the camera sees the ground) marks the pieces cut by the view.
// All three are rasters of `raster`.
PieceSplit SplitPaint(const GroundRaster& raster, const cv::Mat& paint, const cv::Mat& probability,
                      const cv::Mat& in_view, const PieceOptions& options);

}  // namespace segmentation
}  // namespace ipm_road_mapper
