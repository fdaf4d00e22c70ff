// Paint probability in, the package's 16UC1 instance mask out (docs/design.md §2 encoding):
// the paint sampled onto the ground raster with the camera's current extrinsic, split into
// pieces, grouped and classified there (paint_pieces, paint_groups, paint_classes), and the
// instances painted back into the image.
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <vector>

#include "ipm_road_mapper/core/geometry/pinhole_camera.h"
#include "ipm_road_mapper/core/io/yaml_options.h"
#include "ipm_road_mapper/segmentation/ground_raster.h"
#include "ipm_road_mapper/segmentation/paint_classes.h"

namespace ipm_road_mapper {
namespace segmentation {

// Every option of the instancer (config/segmentation.yaml, section `instances`).
struct InstanceOptions {
  double paint_threshold = 0.5;  // a pixel is paint when its probability is above
  GroundRasterOptions raster;
  PieceOptions pieces;
  GroupOptions groups;
  ClassifyOptions classes;
  // The mask class id of each PaintClass (in its enum order); defaults: the package's
  // config/classes.yaml (lane_white_solid 1, lane_white_dashed 2, crosswalk_stripe 20,
  // stop_line 21, arrow_straight 10, hatched_area 30).
  std::array<int, kPaintClassCount> class_ids{{1, 2, 20, 21, 10, 30}};
};

// Reads the `instances` section; throws OptionsError naming a bad or unknown key.
InstanceOptions LoadInstanceOptions(OptionsReader reader);

// One instance of the mask.
struct SegmentedInstance {
  std::uint16_t value = 0;  // class_id * 1000 + index, as in the mask
  int class_id = 0;
  PaintClass paint_class = PaintClass::kLaneSolid;
  double confidence = 0.0;
  int pixels = 0;
};

// What one frame (or a run, summed) gave and left out.
struct InstanceCounters {
  long frames = 0;
  long pieces = 0;
  long speckle = 0;
  ClassifyCounters dropped;
  std::array<long, kPaintClassCount> instances{};  // by PaintClass

  void Add(const InstanceCounters& other);
};

struct SegmentedFrame {
  cv::Mat mask;  // CV_16UC1, image size
  // With KeepGroundView: the raster (far at the top, left at the left) holding each cell's
  // instance value, 1 for paint in no instance (CV_16UC1).
  cv::Mat ground_view;
  std::vector<SegmentedInstance> instances;
  InstanceCounters counters;
};

// Keeps the ground raster of the last extrinsic (rebuilt when it moves by more than
// 0.001 rad or m).
class PaintInstancer {
 public:
  explicit PaintInstancer(const InstanceOptions& options) : options_(options) {}

  // `paint_probability`: CV_32F, the camera's image size, in [0, 1].
  SegmentedFrame Run(const cv::Mat& paint_probability, const PinholeCamera& camera,
                     const Eigen::Isometry3d& T_base_cam);

  const InstanceOptions& options() const { return options_; }
  // Fills SegmentedFrame::ground_view (for a person looking at the split: --debug-dir).
  void KeepGroundView(bool keep) { keep_ground_view_ = keep; }

 private:
  InstanceOptions options_;
  bool keep_ground_view_ = false;
  std::unique_ptr<GroundRaster> raster_;
  cv::Mat in_view_;
};

}  // namespace segmentation
}  // namespace ipm_road_mapper
