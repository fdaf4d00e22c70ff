// Vehicles ahead of the ego vehicle in a synthetic drive (scenario `occluders`): boxes on
// the road that hide what is behind them from the camera.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "ipm_road_mapper/sim/road.h"
#include "ipm_road_mapper/sim/scenario.h"

namespace ipm_road_mapper {
namespace sim {

// The arc length of the occluder's rear when the camera is at `s_cam`, `t_s` seconds after
// the first frame: s_cam + gap_m + gap_amplitude_m sin(2 pi t / gap_period_s).
double OccluderRearS(const OccluderOptions& occluder, double s_cam, double t_s);

// The six faces (map frame, each a convex quadrilateral) of the occluder's box at that
// moment: its footprint is the road patch [rear, rear + length] x [l - width/2, l + width/2]
// on the surface, its top `height_m` above. Empty when the occluder is not present (its
// rear outside [start_s_m, end_s_m]).
//
// Filling the faces' projection with background is exact occlusion for a road point: a ray
// to a surface point runs above the surface until it reaches it, so the box can only be
// on it before the point, that is in front of it (up to the relief under the footprint).
std::vector<std::vector<Eigen::Vector3d>> OccluderFaces(const RoadModel& road,
                                                        const OccluderOptions& occluder,
                                                        double s_cam, double t_s);

}  // namespace sim
}  // namespace ipm_road_mapper
