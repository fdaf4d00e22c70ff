// Data association of one frame's observations with the map's elements: gated and
// class-aware, one-to-one within a frame (greedy by increasing cost).
//  - markings: Mahalanobis distance of the centers in x-y, with the covariance of plain IPM
//    at each (Omega_p: at 20 m a pitch error of 0.3 deg moves a marking 1.4 m along the
//    road but 4 cm across it) plus an isotropic floor; then the best cyclic order of the
//    corners;
//  - lanes: lateral distance of the observation's points to the element's spline (or to
//    its end tangent, for points just past an end), in units of each point's lateral IPM
//    sigma (outer lines seen at 10 m stray by +-0.5 m as the body pitches), and direction
//    agreement.
#pragma once

#include <Eigen/Core>
#include <array>
#include <vector>

#include "ipm_road_mapper/core/io/yaml_options.h"
#include "ipm_road_mapper/core/map/road_map.h"

namespace ipm_road_mapper {

// Gates of the association (config section `association`).
struct AssociationOptions {
  double marking_gate_sigmas = 3.0;  // max Mahalanobis distance of the centers
  // Isotropic floor of the gate's covariance (shape, segmentation), to which the odometry's
  // pose noise is added (MarkingFloorSigma); crosswalk stripes 1 m apart must stay apart:
  // with the default odometry, 3 sigma of the floor is 0.75 m.
  double marking_position_sigma_m = 0.2;
  // Two elements of one class whose centers come closer than this are merged (crosswalk
  // stripes are 1 m apart).
  double marking_merge_distance_m = 0.5;
  // ... or whose ground rectangles overlap by at least this fraction of the smaller one's
  // area (a marking seen as two, e.g. a close-range view that missed its element; real
  // markings do not overlap). 0 = off.
  double marking_merge_overlap = 0.5;
  // Lane points whose tr(Omega_p) exceeds this are not used to associate (or start) a lane:
  // far points of outer lines stray laterally by up to a meter.
  double lane_max_point_score_m2 = 1.0;
  // Max median lateral distance to the lane (hard cap; raised to lane_gate_sigmas floor
  // sigmas when the odometry is noisier than that).
  double lane_gate_m = 1.2;
  double lane_gate_sigmas = 3.0;        // max median lateral distance in IPM sigmas (below)
  double lane_position_sigma_m = 0.05;  // floor of a point's lateral sigma (lane noise); + odometry
  // The odometry's translation noise (m, x-y), added to both floors. Not read from the
  // `association` section: the Mapper sets it from backend.pose_prior_sigma_trans_m, so a
  // user states the odometry's noise once and every gate follows it (at 0.5 m of per-pose
  // error, gates for 0.15 m split every lane into pieces).
  double odometry_sigma_m = 0.15;
  double lane_min_direction_cos = 0.9;  // min |cos| between observation and lane directions
  double lane_max_end_gap_m = 15.0;     // points this far past a lane end still count (growth)
  double lane_min_support = 0.3;        // fraction of the observation's points that must count
  int spurious_after_frames = 10;       // element seen once, unseen for this many frames: dropped
};

// The gates' isotropic floors: the configured sigma and the odometry's, in quadrature.
double MarkingFloorSigma(const AssociationOptions& options);
double LaneFloorSigma(const AssociationOptions& options);

// The lane gate (m): lane_gate_m, widened to lane_gate_sigmas floor sigmas when the
// odometry is noisier than that.
double LaneGateM(const AssociationOptions& options);
// The share of the lane gate that the floor noise takes, lane_gate_sigmas * LaneFloorSigma /
// LaneGateM, in (0, 1]: 1 where the odometry's noise sets the gate.
double LaneNoiseShare(const AssociationOptions& options);

// The length of lane over which the line past an end is fitted (lane_end_line.h):
// lane_max_end_gap_m times the square of LaneNoiseShare. At the default odometry noise
// (share 0.4: 2.3 m) it is under the 3 m chord spacing, the last chord's line, the end
// tangent; when the noise sets the gate (share 1: 0.4 m of noise and more) it is the whole
// reach past the end, over which a curled end point barely turns the line. The square is
// chosen on measured drives (docs/backend.md, "The end's line at high odometry noise"):
// shorter lines split lanes at high noise, longer ones at the default noise on arcs.
double LaneEndLineLength(const AssociationOptions& options);

// Reads the `association` section; throws OptionsError naming the bad key.
AssociationOptions LoadAssociationOptions(OptionsReader reader);

// The cyclic shift s minimizing sum_i |element[i] - observation[(i + s) % 4]|; writes the
// mean corner distance of that order to *mean_distance_m.
int BestCyclicShift(const std::array<Eigen::Vector3d, 4>& element,
                    const std::array<Eigen::Vector3d, 4>& observation, double* mean_distance_m);

// A marking observation in the map frame, for association.
struct MarkingCandidate {
  int class_id = 0;
  std::array<Eigen::Vector3d, 4> corners_map;
  Eigen::Matrix2d center_cov_map = Eigen::Matrix2d::Zero();  // Omega_p (x-y) in the map frame
  bool complete = true;  // every side measured (not a partial view)
  std::array<bool, 4> side_measured{{true, true, true, true}};  // which sides are real (cut: false)
};

// Area of the intersection of two ground rectangles (x-y), over the smaller one's area.
double OverlapOfSmaller(const std::array<Eigen::Vector3d, 4>& a,
                        const std::array<Eigen::Vector3d, 4>& b);

// Squared Mahalanobis distance of a candidate's center from an element's, in x-y.
double MarkingAssociationCost(const MarkingElement& element, const MarkingCandidate& candidate,
                              const AssociationOptions& options);

// For each candidate, the index of its marking element or -1 (new element). Where the
// candidate or the element is a partial view, their centers need not agree: the pair is
// also gated by overlap (at least association.marking_merge_overlap of the smaller one).
std::vector<int> AssociateMarkings(const std::vector<MarkingElement>& elements,
                                   const std::vector<MarkingCandidate>& candidates,
                                   const AssociationOptions& options);
// The same over elements held elsewhere (e.g. the live ones and the retired ones near the
// candidates); indices refer to `elements`.
std::vector<int> AssociateMarkings(const std::vector<const MarkingElement*>& elements,
                                   const std::vector<MarkingCandidate>& candidates,
                                   const AssociationOptions& options);
// A horizontal distance beyond which a candidate's center cannot pass the marking gate of
// any element whose covariance trace is at most max_element_cov_trace: the gate is
// d^T S^-1 d <= g^2, so |d|^2 <= g^2 lambda_max(S) <= g^2 tr(S).
double MarkingGateRadius(const MarkingCandidate& candidate, double max_element_cov_trace,
                         const AssociationOptions& options);

// A lane observation in the map frame, for association.
struct LaneCandidate {
  int class_id = 0;
  std::vector<Eigen::Vector3d> points_map;  // ordered along the lane
  // Per point: low enough IPM uncertainty to associate with (empty: all points are).
  std::vector<bool> usable;
  // Per point: x-y block of Omega_p in the map frame (empty: zero).
  std::vector<Eigen::Matrix2d> cov_map;
};

// Cost of explaining `candidate` by `lane`: the median lateral distance in sigmas (the
// point's lateral Omega_p plus lane_position_sigma_m^2; past an end, up to
// lane_max_end_gap_m, to the line fitted to the lane's last LaneEndLineLength, as is the
// direction test there); negative when the lane is not a
// candidate (class, direction, support, or either gate fails: lane_gate_sigmas on that
// median, lane_gate_m on the median in meters).
double LaneAssociationCost(const LaneElement& lane, const LaneCandidate& candidate,
                           const AssociationOptions& options);

// The median signed distance (m) along `left` (unit, x-y) from the candidate's usable points
// to the lane's curve, over the points beside the lane (not past its ends): how far the
// frame's observation must move across to lie on the lane. NaN with fewer than two such
// points.
double LaneOffsetAcross(const LaneElement& lane, const LaneCandidate& candidate,
                        const Eigen::Vector2d& left);

// For each candidate, the index of its lane element or -1 (new element).
std::vector<int> AssociateLanes(const std::vector<LaneElement>& lanes,
                                const std::vector<LaneCandidate>& candidates,
                                const AssociationOptions& options);
// The same among the lanes `among` (ascending indices into `lanes`, e.g. the lanes near the
// frame); the result indexes `lanes`. The same result as above when `among` holds every lane
// that can pass a candidate's gates.
std::vector<int> AssociateLanes(const std::vector<LaneElement>& lanes,
                                const std::vector<std::size_t>& among,
                                const std::vector<LaneCandidate>& candidates,
                                const AssociationOptions& options);

}  // namespace ipm_road_mapper
