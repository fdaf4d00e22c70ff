// The terminal table of FormatMetricsTable: one section per metric group, two value
// columns (the map / refined result, and the input odometry / initial extrinsic).
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>

#include "ipm_road_mapper/eval/evaluation.h"

namespace ipm_road_mapper {
namespace {

constexpr int kLabelWidth = 40;
constexpr int kValueWidth = 18;

// printf-style formatting of one value; "n/a" for NaN.
std::string Fixed(double value, int decimals) {
  if (!std::isfinite(value)) return "n/a";
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.*f", decimals, value);
  return buffer;
}

std::string MeanStd(const ErrorSummary& s, int decimals = 3) {
  if (s.count == 0) return "n/a";
  return Fixed(s.mean, decimals) + " +- " + Fixed(s.stddev, decimals);
}

std::string Triple(const Eigen::Vector3d& v, int decimals) {
  return Fixed(v.x(), decimals) + " " + Fixed(v.y(), decimals) + " " + Fixed(v.z(), decimals);
}

std::string Count(int numerator, int denominator) {
  return std::to_string(numerator) + "/" + std::to_string(denominator);
}

// Accumulates aligned rows.
class Table {
 public:
  void Section(const std::string& title, const std::string& value_header = "",
               const std::string& reference_header = "") {
    out_ << '\n';
    Line(title, value_header, reference_header, "");
  }
  void Row(const std::string& label, const std::string& value, const std::string& reference,
           const std::string& unit) {
    Line("  " + label, value, reference, unit);
  }
  std::string str() const { return out_.str(); }

 private:
  void Line(const std::string& label, const std::string& value, const std::string& reference,
            const std::string& unit) {
    char buffer[256];
    std::snprintf(buffer, sizeof(buffer), "%-*s %*s %*s  %s", kLabelWidth, label.c_str(),
                  kValueWidth, value.c_str(), kValueWidth, reference.c_str(), unit.c_str());
    std::string line = buffer;
    line.erase(line.find_last_not_of(' ') + 1);
    out_ << line << '\n';
  }
  std::ostringstream out_;
};

void AddMarkingRows(const Metrics& metrics, Table* t) {
  const MarkingMetrics& m = metrics.markings;
  t->Section("Markings (gate " + Fixed(metrics.options.marking_gate_m, 1) + " m)", "map");
  t->Row("center APE mean +- std", MeanStd(m.center_error_m), "", "m");
  t->Row("center APE median / max",
         Fixed(m.center_error_m.median, 3) + " / " + Fixed(m.center_error_m.max, 3), "", "m");
  t->Row("mean |error| x y z", Triple(m.mean_abs_error_xyz_m, 3), "", "m");
  t->Row("mean signed error x y z", Triple(m.signed_mean_error_xyz_m, 3), "", "m");
  t->Row("corner error mean +- std", MeanStd(m.corner_error_m), "", "m");
  t->Row("recall (matched / GT seen)",
         Fixed(m.recall, 3) + " (" + Count(m.matched_visible, m.gt_visible) + ")", "", "");
  t->Row("map markings: matched / all", Count(m.matched, m.map_total), "", "");
  t->Row("unmatched / of which duplicates",
         std::to_string(m.unmatched_map) + " / " + std::to_string(m.duplicates), "", "");
  t->Row("matched but not closed (complete: false)", std::to_string(m.matched_incomplete), "", "");
  t->Row("center APE mean, closed markings only", Fixed(m.center_error_complete_m.mean, 3), "",
         "m");
}

void AddLaneRows(const Metrics& metrics, Table* t) {
  const LaneMetrics& l = metrics.lanes;
  t->Section("Lanes (samples every " + Fixed(metrics.options.lane_sample_spacing_m, 2) + " m)",
             "map");
  t->Row("APE mean +- std (" + std::to_string(l.error_m.count) + " samples)", MeanStd(l.error_m),
         "", "m");
  t->Row("APE median / max", Fixed(l.error_m.median, 3) + " / " + Fixed(l.error_m.max, 3), "", "m");
  t->Row("APE horizontal / vertical mean",
         Fixed(l.error_xy_mean_m, 3) + " / " + Fixed(l.error_z_mean_m, 3), "", "m");
  t->Row("laid by a join (unmeasured): length / APE",
         Fixed(l.unmeasured_length_m, 1) + " m / " + Fixed(l.error_unmeasured_m.mean, 3), "", "m");
  t->Row("APE mean where measured", Fixed(l.error_measured_m.mean, 3), "", "m");
  t->Row("F1", Fixed(l.f1, 3), "", "");
  t->Row("precision (splines on GT / all)",
         Fixed(l.precision, 3) + " (" + Count(l.map_true_positive, l.map_total) + ")", "", "");
  t->Row("recall (GT lanes covered / all)",
         Fixed(l.recall, 3) + " (" + Count(l.gt_matched, l.gt_total) + ")", "", "");
  t->Row("splines per covered GT lane", Fixed(l.splines_per_matched_gt_lane, 2), "", "");
  const LaneletMetrics& ll = metrics.lanelets;
  t->Row("lanelets (map / GT, lanelet_pairing.h)",
         std::to_string(ll.map_total) + " / " + std::to_string(ll.gt_total), "", "");
  t->Row("lanelet recall / precision (centerline length)",
         Fixed(ll.recall, 3) + " / " + Fixed(ll.precision, 3), "", "");
  t->Row("lanelets per covered GT lanelet", Fixed(ll.lanelets_per_covered_gt_lanelet, 2), "", "");
}

// What a map of exactly the road in view would score (view_ceiling.h), beside the map's.
void AddCeilingRows(const Metrics& metrics, Table* t) {
  const ViewCeilingMetrics& c = metrics.ceiling;
  t->Section("The view's ceiling (road in view within " + Fixed(c.view_range_m, 0) + " m)", "map",
             "ceiling");
  t->Row("marking recall", Count(metrics.markings.matched_visible, metrics.markings.gt_visible),
         Count(c.markings_reachable, c.markings_visible), "");
  t->Row("lane recall", Count(metrics.lanes.gt_matched, metrics.lanes.gt_total),
         Count(c.lanes_reachable, c.lanes_total), "");
  t->Row("lane F1 (ceiling: precision 1)", Fixed(metrics.lanes.f1, 3), Fixed(c.lane_f1, 3), "");
  const SeenPartMetrics& p = metrics.seen_parts;
  t->Row("markings on their seen part / seen", Count(p.matched, p.gt_seen), "", "");
  t->Row("center APE to the seen part's center", Fixed(p.center_error_mean_m, 3), "", "m");
}

void AddExtrinsicRows(const Metrics& metrics, Table* t) {
  const ExtrinsicMetrics& e = metrics.extrinsic;
  t->Section("Extrinsic T_base_cam", "refined", "initial");
  t->Row("rotation error", Fixed(e.rot_err_deg, 3), Fixed(e.rot_err_deg_initial, 3), "deg");
  t->Row("roll pitch yaw error", Triple(e.rpy_err_deg, 2), Triple(e.rpy_err_deg_initial, 2), "deg");
  t->Row("translation error", Fixed(e.trans_err_m, 3), Fixed(e.trans_err_m_initial, 3), "m");
  t->Row("IPM grid error mean (" + std::to_string(e.ipm_grid_pixels) + " px, " +
             Fixed(metrics.options.ipm_grid_min_ahead_m, 0) + "-" +
             Fixed(metrics.options.ipm_grid_max_ahead_m, 0) + " m)",
         Fixed(e.ipm_grid_err_m.mean, 3), Fixed(e.ipm_grid_err_m_initial.mean, 3), "m");
  t->Row("IPM grid error max", Fixed(e.ipm_grid_err_m.max, 3),
         Fixed(e.ipm_grid_err_m_initial.max, 3), "m");
  if (e.nees_dof > 0) {
    std::string sigmas;
    for (int i = 0; i < 6; ++i) sigmas += (i ? " " : "") + Fixed(e.err_sigmas(i), 1);
    t->Row("error / its reported sigma (r p y x y z)", sigmas, "", "");
    t->Row("NEES of the observed axes (" + std::to_string(e.nees_dof) + " dof)",
           Fixed(e.nees_observed, 1), "", "");
  }
  if (e.ipm_grid_failed + e.ipm_grid_failed_initial > 0) {
    t->Row("IPM grid pixels above the horizon", std::to_string(e.ipm_grid_failed),
           std::to_string(e.ipm_grid_failed_initial), "");
  }
}

void AddPoseRows(const Metrics& metrics, Table* t) {
  const PoseMetrics& p = metrics.poses;
  const std::string frames = std::to_string(p.frames.size()) + " frames";
  if (!p.has_trajectory) {
    t->Section("Poses (" + frames + "; the map has no trajectory)", "corrected", "odometry");
  } else {
    t->Section("Poses (" + frames + " matched by stamp)", "corrected", "odometry");
  }
  t->Row("translation error mean", Fixed(p.trans_err_m.mean, 3), Fixed(p.trans_err_m_input.mean, 3),
         "m");
  t->Row("translation error max", Fixed(p.trans_err_m.max, 3), Fixed(p.trans_err_m_input.max, 3),
         "m");
  t->Row("  along the heading", Fixed(p.along_err_m.mean, 3), Fixed(p.along_err_m_input.mean, 3),
         "m");
  t->Row("  across the heading", Fixed(p.across_err_m.mean, 3), Fixed(p.across_err_m_input.mean, 3),
         "m");
  t->Row("translation error mean, " + std::to_string(p.frames_moving) + " moving frames",
         Fixed(p.trans_err_moving_m.mean, 3), Fixed(p.trans_err_moving_m_input.mean, 3), "m");
  t->Row("rotation error mean", Fixed(p.rot_err_deg.mean, 3), Fixed(p.rot_err_deg_input.mean, 3),
         "deg");
  t->Row("yaw error mean", Fixed(p.yaw_err_deg.mean, 3), Fixed(p.yaw_err_deg_input.mean, 3), "deg");
  if (p.map_poses_unmatched > 0) {
    t->Row("map poses without a GT frame", std::to_string(p.map_poses_unmatched), "", "");
  }
}

void AddStorageRows(const Metrics& metrics, Table* t) {
  const StorageMetrics& s = metrics.storage;
  t->Section("Storage", "map");
  t->Row(s.map_bytes_from_file ? "map file size" : "map size (serialized)",
         std::to_string(s.map_bytes), "", "B");
  t->Row("mapped lane length", Fixed(s.lane_km, 3), "", "km");
  t->Row("map bytes per km of lane", Fixed(s.map_bytes_per_km, 0), "", "B/km");
  t->Row("control points per km of lane", Fixed(s.control_points_per_km, 1), "", "1/km");
}

}  // namespace

std::string FormatMetricsTable(const Metrics& metrics) {
  Table table;
  AddMarkingRows(metrics, &table);
  AddLaneRows(metrics, &table);
  AddCeilingRows(metrics, &table);
  AddExtrinsicRows(metrics, &table);
  AddPoseRows(metrics, &table);
  AddStorageRows(metrics, &table);
  return "Map evaluation" + table.str();
}

}  // namespace ipm_road_mapper
