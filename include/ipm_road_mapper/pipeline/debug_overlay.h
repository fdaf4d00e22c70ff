// The debug image (the paper's measurement-vs-projection figure): the map projected into
// one camera frame with the refined extrinsic and the frame's corrected pose, over the
// camera image, next to what the front end measured in that frame's mask:
// - green: mapped marking rectangles and lane splines, projected;
// - magenta: the measured marking corners (the 4 image-plane corners of each instance's
//   ground rectangle) and lane centerline pixels;
// - yellow: a line from each measurement to its projection (marking corners matched in the
//   best cyclic order; lane pixels to the nearest projected lane within a gate).
// OpenCV only, no ROS; the nodelet publishes the result as ~debug_image.
#pragma once

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "ipm_road_mapper/core/frontend/class_table.h"
#include "ipm_road_mapper/core/frontend/observations.h"
#include "ipm_road_mapper/core/geometry/pinhole_camera.h"
#include "ipm_road_mapper/core/map/vector_map.h"
#include "ipm_road_mapper/core/mapper/mapper_options.h"

namespace ipm_road_mapper {

// The frame to draw.
struct OverlayFrame {
  cv::Mat image;  // CV_8UC1 or CV_8UC3 (BGR) of the camera's size; empty: the mask is shown
  cv::Mat mask;   // CV_16UC1 instance mask (background when there is no image)
  CameraIntrinsics camera;
  Eigen::Isometry3d T_base_cam = Eigen::Isometry3d::Identity();  // refined extrinsic
  Eigen::Isometry3d T_map_base = Eigen::Isometry3d::Identity();  // corrected frame pose
};

// What was drawn (also what tests check).
struct OverlayStats {
  int markings_projected = 0;  // mapped markings with all 4 corners in front of the camera
  int lanes_projected = 0;     // projected lane pieces (a lane may give several)
  int markings_measured = 0;
  int lane_points_measured = 0;
  int marking_matches = 0;               // measured markings matched to a mapped one
  double mean_corner_residual_px = 0.0;  // over matched corners (0 without a match)
  int lane_point_matches = 0;
  double mean_lane_residual_px = 0.0;  // pixel to projected lane distance, over matches
};

// The front end's measurements of a frame (ExtractObservations with the mapper's options),
// as the mapper would make them with this extrinsic.
FrameObservations MeasureFrame(const cv::Mat& mask, const CameraIntrinsics& camera,
                               const Eigen::Isometry3d& T_base_cam, const ClassTable& classes,
                               const MapperOptions& options);

// Draws the overlay (see the file comment) as a CV_8UC3 BGR image of the camera's size.
// Never throws on bad input: an unusable camera or pose gives a black image with a note.
cv::Mat DrawDebugOverlay(const OverlayFrame& frame, const FrameObservations& measured,
                         const VectorMap& map, OverlayStats* stats = nullptr);

}  // namespace ipm_road_mapper
