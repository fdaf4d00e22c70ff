// Split instances, a segmentation-noise knob of the synthetic drives
// (segmentation.split_instance_prob): one painted element comes out of the "network" as two
// instances, as when an occluder or a worn patch cuts it.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace ipm_road_mapper {
namespace sim {

// Relabels to `new_value` the pixels of `mask` (CV_16UC1, or a region of one) holding
// `value` that lie on the positive side of the line through their centroid with normal
// `normal` ((p - centroid) . normal > 0, p = (column, row)). Returns how many it relabelled.
int SplitInstance(int value, int new_value, const Eigen::Vector2d& normal, cv::Mat* mask);

}  // namespace sim
}  // namespace ipm_road_mapper
