// Accuracy of an exported map against the ground truth of a drive (docs/design.md §5): marking
// and lane APE, lane F1, extrinsic and IPM error, pose error, storage. The definitions and
// the JSON keys are documented in docs/file_formats.md ("Metrics JSON").
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "ipm_road_mapper/core/io/ground_truth.h"
#include "ipm_road_mapper/core/map/vector_map.h"
#include "ipm_road_mapper/eval/view_ceiling.h"

namespace ipm_road_mapper {

// Gates and sampling of the evaluation; the defaults are the project's benchmark settings.
struct EvaluationOptions {
  double marking_gate_m = 2.0;             // largest center distance of a marking match
  double lane_sample_spacing_m = 0.1;      // arc-length spacing of mapped-spline samples
  double lane_match_distance_m = 0.5;      // a point this close to a lane lies "on" it
  double lane_match_fraction = 0.75;       // share of points on the other side for a lane match
  double lane_cover_min_length_m = 1.0;    // spline length on a GT lane to count as covering it
  double lane_max_link_m = 1.0;            // lane points farther apart are not joined by a line
  double pose_stamp_tolerance_s = 1e-3;    // map pose <-> GT frame stamp association
  double pose_moving_min_speed_mps = 0.5;  // a GT frame moves at this true speed or faster
  int ipm_grid_step_px = 40;               // pixel grid spacing of the IPM error
  double ipm_grid_min_ahead_m = 5.0;       // grid pixels whose true ground point is this far
  double ipm_grid_max_ahead_m = 30.0;      //   ahead (base_link x) are used
  std::int64_t map_bytes = -1;             // size of the map file; < 0: size of the serialized map
  // Most mapped-spline samples over all lanes (100 km at 0.1 m, about 1.5 s of sampling and
  // queries); a map needing more is refused with a MapFormatError before any sampling.
  double max_lane_samples = 1e6;
  // The view's ceiling (view_ceiling.h): ground farther than this from base_link is out of
  // view (config/mapper.yaml's ipm.max_range_m), and a marking's in-view part is sampled on
  // a grid this fine.
  double view_range_m = 40.0;
  double view_marking_sample_spacing_m = 0.1;
};

// Value of a metric that cannot be computed (no data); written as null in the JSON.
inline constexpr double kNoValue = std::numeric_limits<double>::quiet_NaN();

// Summary of a set of non-negative errors; NaN fields when `count` is 0.
struct ErrorSummary {
  int count = 0;
  double mean = kNoValue;
  double stddev = kNoValue;  // population standard deviation
  double rmse = kNoValue;
  double median = kNoValue;
  double max = kNoValue;
};

// Mean, std, RMSE, median and max of `values`.
ErrorSummary Summarize(std::vector<double> values);

// How one mapped marking was judged.
enum class MarkingVerdict { kMatched, kDuplicate, kFalsePositive };

// Per mapped marking: its match and errors (errors NaN unless matched).
struct MapMarkingResult {
  std::uint64_t map_id = 0;
  int class_id = 0;
  std::string class_name;
  MarkingVerdict verdict = MarkingVerdict::kFalsePositive;
  int gt_id = -1;  // matched GT marking (or the one duplicated)
  Eigen::Vector3d center_map = Eigen::Vector3d::Zero();
  Eigen::Vector3d center_error_map = Eigen::Vector3d::Constant(kNoValue);  // map - GT
  double center_error_m = kNoValue;
  double corner_error_m = kNoValue;  // mean corner distance, best cyclic order
  bool complete = true;              // the map says every side was measured (MapMarking::Complete)
};

// Per GT marking: whether the map has it.
struct GroundTruthMarkingResult {
  int gt_id = 0;
  int class_id = 0;
  std::string class_name;
  int visible_frames = 0;
  bool matched = false;
  std::uint64_t map_id = 0;  // valid when matched
  int duplicates = 0;        // further map markings of its class within the gate
};

// Marking APE, recall and counts.
struct MarkingMetrics {
  int gt_total = 0;
  int gt_visible = 0;  // GT markings with visible_frames > 0 (recall denominator)
  int map_total = 0;
  int matched = 0;
  int matched_visible = 0;
  int unmatched_map = 0;  // map markings without a match (duplicates included)
  int duplicates = 0;
  // Matched markings whose extent the map did not close (`complete: false`): their center is
  // a lower-bound rectangle's, so they are counted and their APE reported apart as well.
  int matched_incomplete = 0;
  ErrorSummary center_error_complete_m;  // center APE over matched complete markings only
  double recall = kNoValue;              // matched_visible / gt_visible
  double precision = kNoValue;           // matched / map_total
  ErrorSummary center_error_m;
  ErrorSummary corner_error_m;
  Eigen::Vector3d mean_abs_error_xyz_m = Eigen::Vector3d::Constant(kNoValue);
  Eigen::Vector3d signed_mean_error_xyz_m = Eigen::Vector3d::Constant(kNoValue);
  std::vector<MapMarkingResult> map_markings;
  std::vector<GroundTruthMarkingResult> gt_markings;
};

// Per mapped lane (spline).
struct MapLaneResult {
  std::uint64_t map_id = 0;
  std::string class_name;
  int control_points = 0;
  double length_m = 0.0;
  ErrorSummary error_m;         // its samples' distances to the GT lanes
  double fraction_on_gt = 0.0;  // share of samples within lane_match_distance_m
  bool true_positive = false;   // fraction_on_gt >= lane_match_fraction
  int nearest_gt_id = -1;       // GT lane nearest to most of its samples
};

// Per GT lane.
struct GroundTruthLaneResult {
  int gt_id = 0;
  std::string class_name;
  double length_m = 0.0;
  double coverage = 0.0;  // share of its points within lane_match_distance_m of the map
  bool matched = false;   // coverage >= lane_match_fraction
  std::vector<std::uint64_t> covering_map_ids;  // splines lying on it for >= cover length
};

// Lane APE and F1 (MonoLaneMapping convention).
struct LaneMetrics {
  ErrorSummary error_m;               // over all samples of all mapped splines
  double error_xy_mean_m = kNoValue;  // horizontal part of the sample error vectors
  double error_z_mean_m = kNoValue;   // |vertical part|
  int gt_total = 0;
  int gt_matched = 0;
  int map_total = 0;
  int map_true_positive = 0;
  double recall = kNoValue;
  double precision = kNoValue;
  double f1 = kNoValue;
  double splines_per_matched_gt_lane = kNoValue;  // mean covering splines; 1 is ideal
  double mapped_length_m = 0.0;
  // The mapped lines' stretches no pixel measured (MapLane::unmeasured, lane_samples.h): their
  // length (samples x spacing) and the sample errors there and elsewhere (with GT).
  double unmeasured_length_m = 0.0;
  ErrorSummary error_unmeasured_m;
  ErrorSummary error_measured_m;
  std::vector<MapLaneResult> map_lanes;
  std::vector<GroundTruthLaneResult> gt_lanes;
};

// Lanelets: what a lane-level map (the Lanelet2 export) gets from the mapped lines. The
// lanelets of the map's lines and those of the GT lines are found by the same rule
// (core/map/lanelet_pairing.h) and compared by their centerlines, sampled every
// kLaneletSampleSpacingM: a sample of one is on the other where a centerline sample of the
// other, running the same way (within 30 deg), lies within lane_match_distance_m.
constexpr double kLaneletSampleSpacingM = 1.0;
struct LaneletMetrics {
  int gt_total = 0;
  int map_total = 0;
  double gt_length_m = 0.0;     // of the GT lanelets' centerlines
  double map_length_m = 0.0;    // of the map lanelets' centerlines
  double recall = kNoValue;     // share of the GT centerlines' length on a map lanelet
  double precision = kNoValue;  // share of the map centerlines' length on a GT lanelet
  // Over the GT lanelets covered for at least lane_match_fraction of their length: the mean
  // number of map lanelets lying on each for at least lane_cover_min_length_m. 1 is ideal; a
  // lane whose lines are broken into pieces is several lanelets.
  double lanelets_per_covered_gt_lanelet = kNoValue;
};

// Refined and initial extrinsic against the truth, and the IPM error they cause.
struct ExtrinsicMetrics {
  double rot_err_deg = kNoValue;
  double trans_err_m = kNoValue;
  double rot_err_deg_initial = kNoValue;
  double trans_err_m_initial = kNoValue;
  Eigen::Vector3d rpy_err_deg = Eigen::Vector3d::Zero();  // of R_est R_true^T, base_link axes
  Eigen::Vector3d rpy_err_deg_initial = Eigen::Vector3d::Zero();
  Eigen::Vector3d trans_err_xyz_m = Eigen::Vector3d::Zero();  // t_est - t_true, base_link
  Eigen::Vector3d trans_err_xyz_m_initial = Eigen::Vector3d::Zero();
  // The true extrinsic as a mapper config states one (input.extrinsic: xyz, rpy_deg with
  // R = Rz(yaw) Ry(pitch) Rx(roll)), so a tool can hand the truth to the mapper.
  Eigen::Vector3d true_xyz_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d true_rpy_deg = Eigen::Vector3d::Zero();
  ErrorSummary ipm_grid_err_m;          // refined extrinsic
  ErrorSummary ipm_grid_err_m_initial;  // extrinsic handed to the mapper
  int ipm_grid_pixels = 0;              // grid pixels in the 5-30 m band under the truth
  int ipm_grid_failed = 0;              // of those, above the horizon under the map's extrinsic
  int ipm_grid_failed_initial = 0;
  // Whether the map's calibration is honest about itself: the error over the map's own
  // covariance (VectorMap::T_base_cam_covariance). Per axis (roll, pitch, yaw, x, y, z; the
  // rotation as the covariance defines it: R_true = Exp(e) R, about base_link's axes) the
  // error in its reported sigmas, signed (NaN without a variance); and the NEES of the axes
  // the map calls observed, e_o^T Sigma_oo^-1 e_o, chi-square with `nees_dof` degrees of
  // freedom when the covariance is consistent (NaN when the map has no covariance).
  Eigen::Matrix<double, 6, 1> err_sigmas = Eigen::Matrix<double, 6, 1>::Constant(kNoValue);
  double nees_observed = kNoValue;
  int nees_dof = 0;
};

// One pose of the map's trajectory matched to a GT frame.
struct PoseFrameError {
  double stamp = 0.0;
  double trans_err_m = 0.0, rot_err_deg = 0.0, yaw_err_deg = 0.0;                    // corrected
  double trans_err_m_input = 0.0, rot_err_deg_input = 0.0, yaw_err_deg_input = 0.0;  // odometry
  bool moving = false;  // the true speed there is at least pose_moving_min_speed_mps
};

// Corrected poses and input odometry against the true poses (no alignment: all share `map`).
struct PoseMetrics {
  bool has_trajectory = false;  // false: corrected errors are absent (NaN / null)
  int frames_matched = 0;       // map poses with a GT frame within the stamp tolerance
  int map_poses_unmatched = 0;
  ErrorSummary trans_err_m, rot_err_deg, yaw_err_deg;
  ErrorSummary trans_err_m_input, rot_err_deg_input, yaw_err_deg_input;
  // |error| along and across the true heading (x, y of the true base_link): slow odometry
  // drift shows along the road (markings fix it) and across it (lanes fix it) differently.
  ErrorSummary along_err_m, across_err_m, along_err_m_input, across_err_m_input;
  // The translation errors over the frames where the vehicle moves (true speed at least
  // EvaluationOptions::pose_moving_min_speed_mps): a standstill's many frames weigh as much
  // as one place in the mean above.
  int frames_moving = 0;
  ErrorSummary trans_err_moving_m, trans_err_moving_m_input;
  std::vector<PoseFrameError> frames;
};

// Size of the map relative to the mapped lane length.
struct StorageMetrics {
  std::int64_t map_bytes = 0;
  bool map_bytes_from_file = false;  // false: size of the serialized map (VectorMapToJson)
  double lane_km = 0.0;              // summed spline arc lengths
  int control_points = 0;            // all lane control points, phantom ends included
  int markings = 0;
  double map_bytes_per_km = kNoValue;
  double control_points_per_km = kNoValue;
};

// Everything EvaluateMap measures.
struct Metrics {
  MarkingMetrics markings;
  LaneMetrics lanes;
  LaneletMetrics lanelets;
  ExtrinsicMetrics extrinsic;
  PoseMetrics poses;
  StorageMetrics storage;
  ViewCeilingMetrics ceiling;
  SeenPartMetrics seen_parts;
  EvaluationOptions options;
};

// A center map markings are matched to: a GT marking's, or the center of its seen part.
struct MarkingTarget {
  Eigen::Vector3d center_map = Eigen::Vector3d::Zero();
  int class_id = 0;
};
// A candidate match: a map marking and a target of its class, centers within the gate.
struct MarkingPair {
  double distance_m = 0.0;
  int map_index = 0;
  int target_index = 0;
};

// All same-class (map marking, target) pairs whose centers are within gate_m, nearest first
// (ties broken by index: deterministic). Targets are searched in a window of +-gate_m in x
// (sorted by center x), so spread-out maps cost O(N log M); a MapFormatError when the pairs
// exceed ten million (markings piled on each other: a hostile map).
std::vector<MarkingPair> GatedMarkingPairs(const VectorMap& map,
                                           const std::vector<MarkingTarget>& targets,
                                           double gate_m);

// Matches mapped markings to GT markings (same class, center within the gate, one-to-one,
// greedily by increasing distance) and measures their errors.
MarkingMetrics EvaluateMarkings(const VectorMap& map, const GroundTruth& gt,
                                const EvaluationOptions& options);

// Samples the mapped splines and measures them against the GT lane polylines.
LaneMetrics EvaluateLanes(const VectorMap& map, const GroundTruth& gt,
                          const EvaluationOptions& options);

// The map's lanelets against the GT's (LaneletMetrics).
LaneletMetrics EvaluateLanelets(const VectorMap& map, const GroundTruth& gt,
                                const EvaluationOptions& options);

// Compares map.T_base_cam and map.T_base_cam_initial with gt.T_base_cam_true.
ExtrinsicMetrics EvaluateExtrinsic(const VectorMap& map, const GroundTruth& gt,
                                   const EvaluationOptions& options);

// Compares map.trajectory and the GT frames' odometry with the true poses.
PoseMetrics EvaluatePoses(const VectorMap& map, const GroundTruth& gt,
                          const EvaluationOptions& options);

// Map bytes and control points per km of mapped lane.
StorageMetrics EvaluateStorage(const VectorMap& map, const EvaluationOptions& options);

// All of the above.
Metrics EvaluateMap(const VectorMap& map, const GroundTruth& gt, const EvaluationOptions& options);

// The metrics JSON (headline keys at the top level, per-element arrays for plotting); NaN
// values become null.
nlohmann::json MetricsToJson(const Metrics& metrics);

// A fixed-width table of the headline metrics for a terminal.
std::string FormatMetricsTable(const Metrics& metrics);

// Exact distance from points to a set of 3D polylines (consecutive points joined by straight
// segments when closer than max_link_m), via a k-d tree over segment midpoints.
class PolylineDistanceIndex {
 public:
  // Result of a query: the closest point on any polyline.
  struct Nearest {
    double distance_m = std::numeric_limits<double>::infinity();
    int polyline = -1;  // index into the polylines given to the constructor
    Eigen::Vector3d point = Eigen::Vector3d::Zero();
  };

  // Indexes the segments of every polyline (a point with no neighbor within max_link_m
  // stays as an isolated point). O(n log n).
  PolylineDistanceIndex(const std::vector<std::vector<Eigen::Vector3d>>& polylines,
                        double max_link_m);

  // The closest polyline point to `query` (polyline -1 when the index is empty).
  Nearest Query(const Eigen::Vector3d& query) const;

 private:
  // A straight piece of a polyline (a == b for an isolated point).
  struct Segment {
    Eigen::Vector3d a, b, mid;
    int polyline;
  };
  // Orders segments_[begin, end) as a k-d subtree split at its middle element.
  void Build(int begin, int end);
  // Descends the subtree [begin, end), nearer side first, pruning by the splitting plane.
  void Search(int begin, int end, const Eigen::Vector3d& query, Nearest* best) const;

  std::vector<Segment> segments_;   // in k-d order: node = middle of its range
  std::vector<int> split_axis_;     // per node (indexed like segments_)
  double max_half_length_m_ = 0.0;  // bounds |segment - query| >= |mid - query| - this
};

}  // namespace ipm_road_mapper
