// A picture of a segmented frame for a person: the camera image with each instance painted
// in its class's colour (lines solid green / dashed cyan, crossing stripes yellow, stop
// lines red, arrows magenta, hatched areas orange) and the paint left out in grey.
#pragma once

#include <opencv2/core.hpp>

#include "ipm_road_mapper/segmentation/paint_instancer.h"

namespace ipm_road_mapper {

// `image`: CV_8UC1 or CV_8UC3; `paint`: CV_8U paint mask of the image (may be empty).
cv::Mat SegmentationOverlay(const cv::Mat& image, const cv::Mat& paint,
                            const segmentation::SegmentedFrame& frame);

}  // namespace ipm_road_mapper
