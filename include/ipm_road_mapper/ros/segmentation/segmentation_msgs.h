// Bridges of the segmentation: camera images to OpenCV, a segmented frame to the mask image
// and its MaskInstances message.
#pragma once

#include <sensor_msgs/Image.h>

#include <opencv2/core.hpp>
#include <string>

#include "ipm_road_mapper/MaskInstances.h"
#include "ipm_road_mapper/segmentation/paint_instancer.h"

namespace ipm_road_mapper {

// A camera image (mono8, bgr8, rgb8, mono16 scaled down, bgra8/rgba8 without alpha) as
// CV_8UC1 or CV_8UC3 BGR. Empty on success, else why not (an unknown encoding, a bad size).
std::string CameraImageToBgr(const sensor_msgs::Image& msg, cv::Mat* image);

// The 16UC1 mask message of a segmented frame, with `header` (the image's).
sensor_msgs::Image SegmentedMaskMsg(const segmentation::SegmentedFrame& frame,
                                    const std_msgs::Header& header);

// Its instances (values, classes, confidences, pixels), with `header`.
MaskInstances SegmentedInstancesMsg(const segmentation::SegmentedFrame& frame,
                                    const std_msgs::Header& header);

}  // namespace ipm_road_mapper
