// The plain-IPM marking error of a drive: how far markings land when mapped by IPM with
// the rough extrinsic and the odometry poses, no optimization (the paper's "IPM" row). The
// generator reports it so that a scenario's difficulty is known; tests bound it.
#pragma once

#include <vector>

#include "ipm_road_mapper/core/io/ground_truth.h"

namespace ipm_road_mapper {
namespace sim {

// Mean and spread of the plain-IPM marking center error.
struct PlainIpmError {
  int markings = 0;        // markings seen in at least one qualifying frame
  int observations = 0;    // qualifying (marking, frame) pairs
  double mean_m = 0.0;     // 3D center error, mean over markings
  double std_m = 0.0;      // its standard deviation over markings
  double mean_xy_m = 0.0;  // horizontal part only
  double std_xy_m = 0.0;
  double max_m = 0.0;
  std::vector<double> per_marking_m;  // in the order of gt.markings (NaN when never seen)
};

// For each marking and each frame where all 4 true corners project into the image (true
// pose, true extrinsic: what the mask shows) no farther than `max_distance_m` from the
// camera: IPM the 4 corner pixels to the ground with the ROUGH extrinsic
// (Ipm::PixelToGround), move them to the map with the ODOMETRY pose, and take their mean.
// The marking's estimate is the mean of those per-frame centers; its error is the distance
// to the true center.
PlainIpmError ComputePlainIpmError(const GroundTruth& gt, double max_distance_m);

}  // namespace sim
}  // namespace ipm_road_mapper
