#include "ipm_road_mapper/segmentation/paint_instancer.h"

#include <algorithm>

namespace ipm_road_mapper {
namespace segmentation {
namespace {

constexpr double kRasterTolerance = 1e-3;

// Per raster cell, the index of its instance (-1: none).
std::vector<int> CellInstances(const std::vector<PaintPiece>& pieces,
                               const std::vector<PaintInstance>& instances, int cells) {
  std::vector<int> cell_instance(cells, -1);
  for (std::size_t k = 0; k < instances.size(); ++k) {
    for (const int piece : instances[k].pieces) {
      for (const int cell : pieces[piece].cells) cell_instance[cell] = static_cast<int>(k);
    }
  }
  return cell_instance;
}

// The instance of an image pixel's cell, or of a 4-neighbour cell (a pixel on the edge of
// a stroke whose own cell sampled the background).
int PixelInstance(const std::vector<int>& cell_instance, int cell, int cols) {
  if (cell_instance[cell] >= 0) return cell_instance[cell];
  const int n = static_cast<int>(cell_instance.size());
  for (const int neighbour : {cell - 1, cell + 1, cell - cols, cell + cols}) {
    if (neighbour >= 0 && neighbour < n && cell_instance[neighbour] >= 0) {
      return cell_instance[neighbour];
    }
  }
  return -1;
}

}  // namespace

void InstanceCounters::Add(const InstanceCounters& other) {
  frames += other.frames;
  pieces += other.pieces;
  speckle += other.speckle;
  dropped.blobs += other.dropped.blobs;
  dropped.short_lines += other.dropped.short_lines;
  dropped.wide_strokes += other.dropped.wide_strokes;
  dropped.low_confidence += other.dropped.low_confidence;
  for (int i = 0; i < kPaintClassCount; ++i) instances[i] += other.instances[i];
}

SegmentedFrame PaintInstancer::Run(const cv::Mat& paint_probability, const PinholeCamera& camera,
                                   const Eigen::Isometry3d& T_base_cam) {
  if (!raster_ || !raster_->Matches(camera, T_base_cam, kRasterTolerance)) {
    raster_ = std::make_unique<GroundRaster>(camera, T_base_cam, options_.raster);
    in_view_ = raster_->ToRaster(cv::Mat(camera.height(), camera.width(), CV_8U, cv::Scalar(255)));
  }
  SegmentedFrame frame;
  frame.counters.frames = 1;
  const cv::Mat paint_image = paint_probability > options_.paint_threshold;
  const cv::Mat paint = raster_->ToRaster(paint_image);
  const cv::Mat probability = raster_->ToRaster(paint_probability);
  PieceSplit split = SplitPaint(*raster_, paint, probability, in_view_, options_.pieces);
  frame.counters.pieces = static_cast<long>(split.pieces.size());
  frame.counters.speckle = split.speckle_pieces;
  const GroundFootprint footprint{camera.intrinsics().fy,
                                  std::max(0.1, T_base_cam.translation().z())};
  const std::vector<PaintInstance> instances = ClassifyPaint(
      split.pieces, options_.groups, options_.classes, footprint, &frame.counters.dropped);
  const std::vector<int> cell_instance =
      CellInstances(split.pieces, instances, raster_->rows() * raster_->cols());

  // Instance values: class_id * 1000 + a running index per class, from 1.
  std::array<int, kPaintClassCount> next_index{};
  frame.instances.resize(instances.size());
  for (std::size_t k = 0; k < instances.size(); ++k) {
    const int c = static_cast<int>(instances[k].paint_class);
    const int index = std::min(999, ++next_index[c]);
    SegmentedInstance& out = frame.instances[k];
    out.class_id = options_.class_ids[c];
    out.value = static_cast<std::uint16_t>(out.class_id * 1000 + index);
    out.paint_class = instances[k].paint_class;
    out.confidence = instances[k].confidence;
    ++frame.counters.instances[c];
  }
  if (keep_ground_view_) {
    frame.ground_view = cv::Mat::zeros(raster_->rows(), raster_->cols(), CV_16UC1);
    for (int cell = 0; cell < raster_->rows() * raster_->cols(); ++cell) {
      if (!paint.data[cell]) continue;
      const int k = cell_instance[cell];
      frame.ground_view.at<std::uint16_t>(cell / raster_->cols(), cell % raster_->cols()) =
          k >= 0 ? frame.instances[k].value : 1;
    }
  }
  frame.mask = cv::Mat::zeros(camera.height(), camera.width(), CV_16UC1);
  const cv::Mat& pixel_cells = raster_->PixelCells();
  for (int v = 0; v < camera.height(); ++v) {
    const uchar* paint_row = paint_image.ptr<uchar>(v);
    const int* cells = pixel_cells.ptr<int>(v);
    std::uint16_t* mask_row = frame.mask.ptr<std::uint16_t>(v);
    for (int u = 0; u < camera.width(); ++u) {
      if (!paint_row[u] || cells[u] < 0) continue;
      const int k = PixelInstance(cell_instance, cells[u], raster_->cols());
      if (k < 0) continue;
      mask_row[u] = frame.instances[k].value;
      ++frame.instances[k].pixels;
    }
  }
  return frame;
}

}  // namespace segmentation
}  // namespace ipm_road_mapper
