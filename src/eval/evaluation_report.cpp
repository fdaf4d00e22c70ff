// The metrics JSON (keys documented in docs/file_formats.md, "Metrics JSON").
#include <cmath>
#include <string>

#include "ipm_road_mapper/eval/evaluation.h"

namespace ipm_road_mapper {
namespace {

// NaN -> null, otherwise the number.
nlohmann::json Number(double value) {
  return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(nullptr);
}

nlohmann::json Vector(const Eigen::Vector3d& v) {
  return nlohmann::json::array({Number(v.x()), Number(v.y()), Number(v.z())});
}

const char* ToString(MarkingVerdict verdict) {
  switch (verdict) {
    case MarkingVerdict::kMatched:
      return "matched";
    case MarkingVerdict::kDuplicate:
      return "duplicate";
    case MarkingVerdict::kFalsePositive:
      return "false_positive";
  }
  return "unknown";
}

// Adds prefix_mean_m-style keys: <prefix>_mean<unit>, _std, _rmse, _median, _max.
void AddSummary(const std::string& prefix, const std::string& unit, const ErrorSummary& s,
                nlohmann::json* j) {
  (*j)[prefix + "_mean" + unit] = Number(s.mean);
  (*j)[prefix + "_std" + unit] = Number(s.stddev);
  (*j)[prefix + "_rmse" + unit] = Number(s.rmse);
  (*j)[prefix + "_median" + unit] = Number(s.median);
  (*j)[prefix + "_max" + unit] = Number(s.max);
}

void AddMarkings(const MarkingMetrics& m, nlohmann::json* j) {
  AddSummary("marking_ape", "_m", m.center_error_m, j);
  AddSummary("marking_corner_err", "_m", m.corner_error_m, j);
  (*j)["marking_ape_abs_xyz_m"] = Vector(m.mean_abs_error_xyz_m);
  (*j)["marking_ape_signed_xyz_m"] = Vector(m.signed_mean_error_xyz_m);
  (*j)["marking_recall"] = Number(m.recall);
  (*j)["marking_precision"] = Number(m.precision);
  (*j)["marking_matched"] = m.matched;
  (*j)["marking_gt_total"] = m.gt_total;
  (*j)["marking_gt_visible"] = m.gt_visible;
  (*j)["marking_map_total"] = m.map_total;
  (*j)["marking_unmatched"] = m.unmatched_map;
  (*j)["marking_duplicates"] = m.duplicates;
  (*j)["marking_matched_incomplete"] = m.matched_incomplete;
  (*j)["marking_ape_complete_mean_m"] = Number(m.center_error_complete_m.mean);
  nlohmann::json markings = nlohmann::json::array();
  for (const MapMarkingResult& r : m.map_markings) {
    markings.push_back({{"map_id", r.map_id},
                        {"class_id", r.class_id},
                        {"class_name", r.class_name},
                        {"verdict", ToString(r.verdict)},
                        {"gt_id", r.gt_id >= 0 ? nlohmann::json(r.gt_id) : nullptr},
                        {"center_map", Vector(r.center_map)},
                        {"center_err_xyz_m", Vector(r.center_error_map)},
                        {"center_err_m", Number(r.center_error_m)},
                        {"corner_err_m", Number(r.corner_error_m)},
                        {"complete", r.complete}});
  }
  (*j)["markings"] = markings;
  nlohmann::json gt_markings = nlohmann::json::array();
  for (const GroundTruthMarkingResult& r : m.gt_markings) {
    gt_markings.push_back({{"gt_id", r.gt_id},
                           {"class_id", r.class_id},
                           {"class_name", r.class_name},
                           {"visible_frames", r.visible_frames},
                           {"matched", r.matched},
                           {"map_id", r.matched ? nlohmann::json(r.map_id) : nullptr},
                           {"duplicates", r.duplicates}});
  }
  (*j)["gt_markings"] = gt_markings;
}

void AddLanelets(const LaneletMetrics& m, nlohmann::json* j) {
  (*j)["lanelet_gt_total"] = m.gt_total;
  (*j)["lanelet_map_total"] = m.map_total;
  (*j)["lanelet_gt_length_m"] = Number(m.gt_length_m);
  (*j)["lanelet_map_length_m"] = Number(m.map_length_m);
  (*j)["lanelet_recall"] = Number(m.recall);
  (*j)["lanelet_precision"] = Number(m.precision);
  (*j)["lanelets_per_covered_gt_lanelet"] = Number(m.lanelets_per_covered_gt_lanelet);
}

void AddLanes(const LaneMetrics& m, nlohmann::json* j) {
  AddSummary("lane_ape", "_m", m.error_m, j);
  (*j)["lane_ape_xy_mean_m"] = Number(m.error_xy_mean_m);
  (*j)["lane_ape_z_mean_m"] = Number(m.error_z_mean_m);
  (*j)["lane_samples"] = m.error_m.count;
  (*j)["lane_unmeasured_length_m"] = Number(m.unmeasured_length_m);
  (*j)["lane_ape_unmeasured_mean_m"] = Number(m.error_unmeasured_m.mean);
  (*j)["lane_ape_unmeasured_samples"] = m.error_unmeasured_m.count;
  (*j)["lane_ape_measured_mean_m"] = Number(m.error_measured_m.mean);
  (*j)["lane_f1"] = Number(m.f1);
  (*j)["lane_precision"] = Number(m.precision);
  (*j)["lane_recall"] = Number(m.recall);
  (*j)["lane_gt_total"] = m.gt_total;
  (*j)["lane_gt_matched"] = m.gt_matched;
  (*j)["lane_map_total"] = m.map_total;
  (*j)["lane_map_true_positive"] = m.map_true_positive;
  (*j)["lane_splines_per_matched_gt_lane"] = Number(m.splines_per_matched_gt_lane);
  nlohmann::json lanes = nlohmann::json::array();
  for (const MapLaneResult& r : m.map_lanes) {
    lanes.push_back(
        {{"map_id", r.map_id},
         {"class_name", r.class_name},
         {"control_points", r.control_points},
         {"length_m", r.length_m},
         {"ape_mean_m", Number(r.error_m.mean)},
         {"ape_std_m", Number(r.error_m.stddev)},
         {"ape_max_m", Number(r.error_m.max)},
         {"fraction_on_gt", r.fraction_on_gt},
         {"true_positive", r.true_positive},
         {"nearest_gt_id", r.nearest_gt_id >= 0 ? nlohmann::json(r.nearest_gt_id) : nullptr}});
  }
  (*j)["lanes"] = lanes;
  nlohmann::json gt_lanes = nlohmann::json::array();
  for (const GroundTruthLaneResult& r : m.gt_lanes) {
    gt_lanes.push_back({{"gt_id", r.gt_id},
                        {"class_name", r.class_name},
                        {"length_m", r.length_m},
                        {"coverage", r.coverage},
                        {"matched", r.matched},
                        {"covering_map_ids", r.covering_map_ids}});
  }
  (*j)["gt_lanes"] = gt_lanes;
}

void AddCeiling(const ViewCeilingMetrics& m, nlohmann::json* j) {
  (*j)["ceiling_view_range_m"] = m.view_range_m;
  (*j)["ceiling_lane_recall"] = Number(m.lane_recall);
  (*j)["ceiling_lane_f1"] = Number(m.lane_f1);
  (*j)["ceiling_lanes_reachable"] = m.lanes_reachable;
  (*j)["ceiling_marking_recall"] = Number(m.marking_recall);
  (*j)["ceiling_markings_reachable"] = m.markings_reachable;
  nlohmann::json lanes = nlohmann::json::array();
  for (const ViewCeilingLane& r : m.lanes) {
    lanes.push_back(
        {{"gt_id", r.gt_id}, {"in_view_fraction", r.in_view_fraction}, {"reachable", r.reachable}});
  }
  (*j)["ceiling_lanes"] = lanes;
  nlohmann::json markings = nlohmann::json::array();
  for (const ViewCeilingMarking& r : m.markings) {
    markings.push_back({{"gt_id", r.gt_id},
                        {"visible_frames", r.visible_frames},
                        {"in_view_fraction", r.in_view_fraction},
                        {"in_view_center_map", Vector(r.in_view_center_map)},
                        {"in_view_center_offset_m", Number(r.in_view_center_offset_m)},
                        {"reachable", r.reachable}});
  }
  (*j)["ceiling_markings"] = markings;
}

void AddSeenParts(const SeenPartMetrics& m, nlohmann::json* j) {
  (*j)["seen_part_gt"] = m.gt_seen;
  (*j)["seen_part_matched"] = m.matched;
  (*j)["seen_part_recall"] = Number(m.recall);
  (*j)["seen_part_ape_mean_m"] = Number(m.center_error_mean_m);
  (*j)["seen_part_ape_max_m"] = Number(m.center_error_max_m);
  nlohmann::json markings = nlohmann::json::array();
  for (const SeenPartMarking& r : m.markings) {
    markings.push_back({{"gt_id", r.gt_id},
                        {"matched", r.matched},
                        {"map_id", r.matched ? nlohmann::json(r.map_id) : nullptr},
                        {"center_err_m", Number(r.center_error_m)}});
  }
  (*j)["seen_part_markings"] = markings;
}

void AddExtrinsic(const ExtrinsicMetrics& m, nlohmann::json* j) {
  (*j)["extrinsic_rot_err_deg"] = Number(m.rot_err_deg);
  (*j)["extrinsic_trans_err_m"] = Number(m.trans_err_m);
  (*j)["extrinsic_rot_err_deg_initial"] = Number(m.rot_err_deg_initial);
  (*j)["extrinsic_trans_err_m_initial"] = Number(m.trans_err_m_initial);
  (*j)["extrinsic_rpy_err_deg"] = Vector(m.rpy_err_deg);
  (*j)["extrinsic_rpy_err_deg_initial"] = Vector(m.rpy_err_deg_initial);
  (*j)["extrinsic_trans_err_xyz_m"] = Vector(m.trans_err_xyz_m);
  (*j)["extrinsic_trans_err_xyz_m_initial"] = Vector(m.trans_err_xyz_m_initial);
  (*j)["extrinsic_true_xyz_m"] = Vector(m.true_xyz_m);
  (*j)["extrinsic_true_rpy_deg"] = Vector(m.true_rpy_deg);
  (*j)["ipm_grid_err_m"] = Number(m.ipm_grid_err_m.mean);
  (*j)["ipm_grid_err_m_initial"] = Number(m.ipm_grid_err_m_initial.mean);
  (*j)["ipm_grid_err_max_m"] = Number(m.ipm_grid_err_m.max);
  (*j)["ipm_grid_err_max_m_initial"] = Number(m.ipm_grid_err_m_initial.max);
  (*j)["ipm_grid_pixels"] = m.ipm_grid_pixels;
  (*j)["ipm_grid_failed"] = m.ipm_grid_failed;
  (*j)["ipm_grid_failed_initial"] = m.ipm_grid_failed_initial;
  nlohmann::json err_sigmas = nlohmann::json::array();
  for (int i = 0; i < 6; ++i) err_sigmas.push_back(Number(m.err_sigmas(i)));
  (*j)["extrinsic_err_sigmas"] = err_sigmas;
  (*j)["extrinsic_nees_observed"] = Number(m.nees_observed);
  (*j)["extrinsic_nees_dof"] = m.nees_dof;
}

void AddPoses(const PoseMetrics& m, nlohmann::json* j) {
  (*j)["pose_has_trajectory"] = m.has_trajectory;
  (*j)["pose_frames_matched"] = m.frames_matched;
  (*j)["pose_map_poses_unmatched"] = m.map_poses_unmatched;
  (*j)["pose_trans_err_m"] = Number(m.trans_err_m.mean);
  (*j)["pose_rot_err_deg"] = Number(m.rot_err_deg.mean);
  (*j)["pose_yaw_err_deg"] = Number(m.yaw_err_deg.mean);
  (*j)["pose_trans_err_max_m"] = Number(m.trans_err_m.max);
  (*j)["pose_trans_err_m_input"] = Number(m.trans_err_m_input.mean);
  (*j)["pose_rot_err_deg_input"] = Number(m.rot_err_deg_input.mean);
  (*j)["pose_yaw_err_deg_input"] = Number(m.yaw_err_deg_input.mean);
  (*j)["pose_trans_err_max_m_input"] = Number(m.trans_err_m_input.max);
  (*j)["pose_along_err_m"] = Number(m.along_err_m.mean);
  (*j)["pose_across_err_m"] = Number(m.across_err_m.mean);
  (*j)["pose_along_err_m_input"] = Number(m.along_err_m_input.mean);
  (*j)["pose_across_err_m_input"] = Number(m.across_err_m_input.mean);
  (*j)["pose_frames_moving"] = m.frames_moving;
  (*j)["pose_trans_err_moving_m"] = Number(m.trans_err_moving_m.mean);
  (*j)["pose_trans_err_moving_m_input"] = Number(m.trans_err_moving_m_input.mean);
  nlohmann::json frames = nlohmann::json::array();
  for (const PoseFrameError& e : m.frames) {
    frames.push_back({{"stamp", e.stamp},
                      {"trans_err_m", Number(e.trans_err_m)},
                      {"rot_err_deg", Number(e.rot_err_deg)},
                      {"yaw_err_deg", Number(e.yaw_err_deg)},
                      {"trans_err_m_input", e.trans_err_m_input},
                      {"rot_err_deg_input", e.rot_err_deg_input},
                      {"yaw_err_deg_input", e.yaw_err_deg_input},
                      {"moving", e.moving}});
  }
  (*j)["poses"] = frames;
}

nlohmann::json OptionsToJson(const EvaluationOptions& o) {
  return {{"marking_gate_m", o.marking_gate_m},
          {"lane_sample_spacing_m", o.lane_sample_spacing_m},
          {"lane_match_distance_m", o.lane_match_distance_m},
          {"lane_match_fraction", o.lane_match_fraction},
          {"lane_cover_min_length_m", o.lane_cover_min_length_m},
          {"lane_max_link_m", o.lane_max_link_m},
          {"pose_stamp_tolerance_s", o.pose_stamp_tolerance_s},
          {"pose_moving_min_speed_mps", o.pose_moving_min_speed_mps},
          {"ipm_grid_step_px", o.ipm_grid_step_px},
          {"ipm_grid_min_ahead_m", o.ipm_grid_min_ahead_m},
          {"ipm_grid_max_ahead_m", o.ipm_grid_max_ahead_m},
          {"view_range_m", o.view_range_m},
          {"view_marking_sample_spacing_m", o.view_marking_sample_spacing_m}};
}

}  // namespace

nlohmann::json MetricsToJson(const Metrics& metrics) {
  nlohmann::json j = nlohmann::json::object();
  AddMarkings(metrics.markings, &j);
  AddLanes(metrics.lanes, &j);
  AddLanelets(metrics.lanelets, &j);
  AddCeiling(metrics.ceiling, &j);
  AddSeenParts(metrics.seen_parts, &j);
  AddExtrinsic(metrics.extrinsic, &j);
  AddPoses(metrics.poses, &j);
  const StorageMetrics& s = metrics.storage;
  j["map_bytes"] = s.map_bytes;
  j["map_bytes_source"] = s.map_bytes_from_file ? "file" : "serialized";
  j["lane_km"] = s.lane_km;
  j["control_points"] = s.control_points;
  j["map_bytes_per_km"] = Number(s.map_bytes_per_km);
  j["control_points_per_km"] = Number(s.control_points_per_km);
  j["options"] = OptionsToJson(metrics.options);
  return j;
}

}  // namespace ipm_road_mapper
