#include "ipm_road_mapper/segmentation/paint_pieces.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <opencv2/imgproc.hpp>

namespace ipm_road_mapper {
namespace segmentation {
namespace {

constexpr double kDegToRad = M_PI / 180.0;

// Union-find over cell indices (path halving) that keeps each set's summed doubled-angle
// direction, so that a set is compared by its mean direction: paint that turns gradually
// (a chevron bending into its edge line through the smoothing) cannot chain two directions
// into one piece cell by cell.
class DirectedSets {
 public:
  explicit DirectedSets(int n) : parent_(n), sum_(n, Eigen::Vector2f::Zero()) {
    std::iota(parent_.begin(), parent_.end(), 0);
  }
  void SetDirection(int i, const Eigen::Vector2f& doubled) { sum_[i] = doubled; }
  int Find(int i) {
    while (parent_[i] != i) i = parent_[i] = parent_[parent_[i]];
    return i;
  }
  // Joins the sets of a and b when their mean directions are within min_dot (cos of twice
  // the angle); undirected sets (zero sums) join only undirected ones.
  void JoinIfAligned(int a, int b, float min_dot) {
    a = Find(a);
    b = Find(b);
    if (a == b) return;
    const float na = sum_[a].norm(), nb = sum_[b].norm();
    const bool directed_a = na > 0.0f, directed_b = nb > 0.0f;
    if (directed_a != directed_b) return;
    if (directed_a && sum_[a].dot(sum_[b]) < min_dot * na * nb) return;
    parent_[a] = b;
    sum_[b] += sum_[a];
  }

 private:
  std::vector<int> parent_;
  std::vector<Eigen::Vector2f> sum_;
};

// Per cell, the doubled stroke angle (cos 2a, sin 2a) of the paint's direction in raster
// coordinates and its coherence, from the structure tensor of the lightly blurred paint.
void StrokeDirections(const cv::Mat& paint, double scale_cells, cv::Mat* cos2, cv::Mat* sin2,
                      cv::Mat* coherence) {
  cv::Mat f;
  paint.convertTo(f, CV_32F, 1.0 / 255.0);
  cv::GaussianBlur(f, f, cv::Size(), 1.0);
  cv::Mat gx, gy;
  cv::Sobel(f, gx, CV_32F, 1, 0, 3);
  cv::Sobel(f, gy, CV_32F, 0, 1, 3);
  cv::Mat jxx = gx.mul(gx), jyy = gy.mul(gy), jxy = gx.mul(gy);
  const cv::Size none;
  cv::GaussianBlur(jxx, jxx, none, scale_cells);
  cv::GaussianBlur(jyy, jyy, none, scale_cells);
  cv::GaussianBlur(jxy, jxy, none, scale_cells);
  cos2->create(paint.size(), CV_32F);
  sin2->create(paint.size(), CV_32F);
  coherence->create(paint.size(), CV_32F);
  for (int r = 0; r < paint.rows; ++r) {
    for (int c = 0; c < paint.cols; ++c) {
      const float a = jxx.at<float>(r, c), b = jyy.at<float>(r, c), d = jxy.at<float>(r, c);
      const float trace = a + b;
      const float diff = std::sqrt((a - b) * (a - b) + 4.0f * d * d);
      // The gradient's doubled angle is (a - b, 2d); the stroke runs across it (+ pi).
      const float norm = diff > 1e-12f ? diff : 1.0f;
      cos2->at<float>(r, c) = -(a - b) / norm;
      sin2->at<float>(r, c) = -2.0f * d / norm;
      coherence->at<float>(r, c) = trace > 1e-9f ? diff / trace : 0.0f;
    }
  }
}

// Ground statistics of the cells of one piece.
PaintPiece MeasurePiece(const GroundRaster& raster, std::vector<int> cells,
                        const cv::Mat& coherence, const cv::Mat& probability,
                        const cv::Mat& in_view) {
  PaintPiece piece;
  const int cols = raster.cols();
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  Eigen::Matrix2d second = Eigen::Matrix2d::Zero();
  double coherent = 0.0, paint_probability = 0.0;
  for (const int cell : cells) {
    const int r = cell / cols, c = cell % cols;
    const Eigen::Vector2d xy = raster.CellCenter(r, c);
    mean += xy;
    second += xy * xy.transpose();
    coherent += coherence.at<float>(r, c);
    paint_probability += probability.empty() ? 1.0 : probability.at<float>(r, c);
    // A cell next to one not in view: the piece goes on where the camera does not see.
    for (const auto& [dr, dc] : {std::pair{-1, 0}, {1, 0}, {0, -1}, {0, 1}}) {
      const int rr = r + dr, cc = c + dc;
      if (rr < 0 || cc < 0 || rr >= raster.rows() || cc >= cols || !in_view.at<uchar>(rr, cc)) {
        piece.touches_edge = true;
      }
    }
  }
  const double n = static_cast<double>(cells.size());
  piece.center = mean / n;
  const Eigen::Matrix2d covariance = second / n - piece.center * piece.center.transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(covariance);
  piece.direction = eigen.eigenvectors().col(1).normalized();
  double lo = 0.0, hi = 0.0;
  for (const int cell : cells) {
    const double s =
        (raster.CellCenter(cell / cols, cell % cols) - piece.center).dot(piece.direction);
    lo = std::min(lo, s);
    hi = std::max(hi, s);
  }
  const double cell_m = raster.cell_m();
  piece.area_m2 = n * cell_m * cell_m;
  piece.length_m = hi - lo + cell_m;
  piece.width_m = piece.area_m2 / piece.length_m;
  piece.center += 0.5 * (hi + lo) * piece.direction;  // the middle of its extent
  piece.coherence = coherent / n;
  piece.paint_probability = paint_probability / n;
  piece.cells = std::move(cells);
  return piece;
}

// Cells within reach of paint wider than a line in every direction (a blob's core: an arrow
// head, a painted area, a curb or shadow blob) have no direction: a blob stays one piece
// instead of its rim turning into strokes.
void ClearBlobDirections(const cv::Mat& paint, double blob_radius_cells, cv::Mat* coherence) {
  cv::Mat distance;
  cv::distanceTransform(paint, distance, cv::DIST_L2, 3);
  cv::Mat core = distance > blob_radius_cells;
  if (cv::countNonZero(core) == 0) return;
  const int reach = static_cast<int>(std::ceil(blob_radius_cells)) + 1;
  cv::dilate(core, core,
             cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * reach + 1, 2 * reach + 1)));
  coherence->setTo(0.0f, core & paint);
}

}  // namespace

PieceSplit SplitPaint(const GroundRaster& raster, const cv::Mat& paint, const cv::Mat& probability,
                      const cv::Mat& in_view, const PieceOptions& options) {
  PieceSplit split;
  cv::Mat cos2, sin2, coherence;
  StrokeDirections(paint, options.orientation_scale_m / raster.cell_m(), &cos2, &sin2, &coherence);
  ClearBlobDirections(paint, options.blob_core_radius_m / raster.cell_m(), &coherence);
  const int rows = paint.rows, cols = paint.cols;
  // Two directions within max_turn: their doubled angles' dot product above cos(2 max_turn).
  const float min_dot = static_cast<float>(std::cos(2.0 * options.max_turn_deg * kDegToRad));
  const float min_coherence = static_cast<float>(options.min_coherence);
  DirectedSets sets(rows * cols);
  for (int r = 0; r < rows; ++r) {
    const uchar* row = paint.ptr<uchar>(r);
    for (int c = 0; c < cols; ++c) {
      if (!row[c] || coherence.at<float>(r, c) < min_coherence) continue;
      sets.SetDirection(r * cols + c, {cos2.at<float>(r, c), sin2.at<float>(r, c)});
    }
  }
  for (int r = 0; r < rows; ++r) {
    const uchar* row = paint.ptr<uchar>(r);
    for (int c = 0; c < cols; ++c) {
      if (!row[c]) continue;
      // The neighbours already visited: left, and the three above.
      for (const auto& [dr, dc] : {std::pair{0, -1}, {-1, -1}, {-1, 0}, {-1, 1}}) {
        const int rr = r + dr, cc = c + dc;
        if (rr < 0 || cc < 0 || cc >= cols || !paint.at<uchar>(rr, cc)) continue;
        sets.JoinIfAligned(r * cols + c, rr * cols + cc, min_dot);
      }
    }
  }
  // Cells by set; an undirected cell left alone joins a directed neighbour's piece later
  // through its own set only, so a blob's rim stays with the blob.
  std::vector<int> root_to_piece(rows * cols, -1);
  std::vector<std::vector<int>> groups;
  for (int r = 0; r < rows; ++r) {
    const uchar* row = paint.ptr<uchar>(r);
    for (int c = 0; c < cols; ++c) {
      if (!row[c]) continue;
      const int root = sets.Find(r * cols + c);
      if (root_to_piece[root] < 0) {
        root_to_piece[root] = static_cast<int>(groups.size());
        groups.emplace_back();
      }
      groups[root_to_piece[root]].push_back(r * cols + c);
    }
  }
  const double cell_area = raster.cell_m() * raster.cell_m();
  for (std::vector<int>& cells : groups) {
    if (cells.size() * cell_area < options.min_area_m2) {
      ++split.speckle_pieces;
      continue;
    }
    split.pieces.push_back(MeasurePiece(raster, std::move(cells), coherence, probability, in_view));
  }
  return split;
}

}  // namespace segmentation
}  // namespace ipm_road_mapper
