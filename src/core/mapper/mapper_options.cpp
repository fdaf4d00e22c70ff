#include "ipm_road_mapper/core/mapper/mapper_options.h"

#include <cmath>
#include <sstream>
#include <vector>

namespace ipm_road_mapper {
namespace {
constexpr double kDegToRad = M_PI / 180.0;
// Control points closer than this make the lane fit and association cost explode (at 1e-4 m
// the mapper ran at 0.2 frames/s) for no accuracy: lanes are drawn in metres.
constexpr double kMinChordSpacingM = 0.5;

std::string CheckChordSpacing(const double& v) {
  if (std::isfinite(v) && v >= kMinChordSpacingM) return "";
  std::ostringstream s;
  s << "must be >= " << kMinChordSpacingM << " m (got " << v << ")";
  return s.str();
}
}  // namespace

const char* ToString(IpmGround ground) {
  return ground == IpmGround::kBaseLink ? "base_link" : "trajectory";
}

IpmOptions LoadIpmOptions(OptionsReader reader) {
  IpmOptions o;
  reader.Read<double>("max_range_m", &o.max_range_m, CheckPositive);
  std::string ground = ToString(o.ground);
  reader.Read<std::string>("ground", &ground, [](const std::string& v) -> std::string {
    return v == "trajectory" || v == "base_link" ? "" : "must be trajectory or base_link";
  });
  o.ground = ground == "base_link" ? IpmGround::kBaseLink : IpmGround::kTrajectory;
  reader.Read<double>("road_grade_length_m", &o.road_plane.grade_length_m, CheckPositive);
  reader.Read<double>("road_cross_slope_window_s", &o.road_plane.cross_slope_window_s,
                      CheckNonNegative);
  std::vector<double> pixel_error{o.error_model.pixel_error_px.x(),
                                  o.error_model.pixel_error_px.y()};
  reader.Read<std::vector<double>>("pixel_error_px", &pixel_error,
                                   [](const std::vector<double>& v) -> std::string {
                                     if (v.size() != 2) return "must be [du, dv]";
                                     if (!std::isfinite(v[0]) || !std::isfinite(v[1])) {
                                       return "must be finite";
                                     }
                                     if (v[0] < 0.0 || v[1] < 0.0) return "must be >= 0";
                                     return "";
                                   });
  o.error_model.pixel_error_px = {pixel_error[0], pixel_error[1]};
  double pitch_sigma_deg = o.error_model.pitch_sigma_rad / kDegToRad;
  reader.Read<double>("pitch_sigma_deg", &pitch_sigma_deg, CheckNonNegative);
  o.error_model.pitch_sigma_rad = pitch_sigma_deg * kDegToRad;
  reader.Read<double>("height_sigma_m", &o.error_model.height_sigma_m, CheckNonNegative);
  // With every error source at zero the covariance Omega_p is singular: its inverse weights
  // association gates and point selection.
  if (o.error_model.pixel_error_px.isZero(0.0) && o.error_model.pitch_sigma_rad == 0.0 &&
      o.error_model.height_sigma_m == 0.0) {
    throw OptionsError((reader.path().empty() ? std::string("ipm") : reader.path()) +
                       ": pixel_error_px, pitch_sigma_deg and height_sigma_m are all 0: at least "
                       "one must be > 0");
  }
  reader.RejectUnknownKeys();
  return o;
}

LaneOptions LoadLaneOptions(OptionsReader reader) {
  LaneOptions o;
  reader.Read<bool>("point_selection", &o.point_selection);
  reader.Read<int>("selected_points_per_frame", &o.selected_points_per_frame, CheckPositiveInt);
  reader.Read<double>("max_selected_score_m2", &o.max_selected_score_m2, CheckPositive);
  reader.Read<double>("chord_spacing_m", &o.fit.chord_spacing_m, CheckChordSpacing);
  reader.Read<double>("smoothing_length_m", &o.fit.smoothing_length_m, CheckPositive);
  o.end_fit.chord_spacing_m = o.fit.chord_spacing_m;
  reader.Read<int>("end_fit_frames", &o.end_fit_frames, CheckPositiveInt);
  reader.Read<double>("end_growth_path_length_m", &o.end_growth_path_length_m, CheckNonNegative);
  reader.Read<int>("end_fit_min_points", &o.end_fit.min_points_to_extend, CheckPositiveInt);
  reader.Read<double>("end_fit_max_point_distance_m", &o.end_fit.max_point_distance_m,
                      CheckPositive);
  reader.Read<double>("end_fit_smoothness", &o.end_fit.smoothness_weight, CheckNonNegative);
  reader.Read<double>("end_fit_prior_sigma_m", &o.end_fit.prior_sigma_m, CheckPositive);
  reader.Read<double>("end_fit_robust_scale_m", &o.end_fit.robust_scale_m, CheckPositive);
  reader.Read<int>("merge_every_n_frames", &o.merge_every_n_frames, CheckPositiveInt);
  reader.Read<double>("min_new_lane_length_m", &o.min_new_lane_length_m, CheckNonNegative);
  reader.Read<bool>("join_enabled", &o.join.enabled);
  reader.Read<double>("join_max_gap_m", &o.join.max_gap_m, CheckNonNegative);
  reader.Read<double>("join_max_hidden_gap_m", &o.join.max_hidden_gap_m, CheckNonNegative);
  reader.Read<double>("join_max_overlap_m", &o.join.max_overlap_m, CheckNonNegative);
  reader.Read<double>("join_end_length_m", &o.join.end_length_m, CheckPositive);
  reader.Read<double>("join_gate_sigmas", &o.join.gate_sigmas, CheckPositive);
  reader.Read<double>("join_ipm_correlation_frames", &o.join.ipm_correlation_frames,
                      CheckNonNegative);
  reader.RejectUnknownKeys();
  return o;
}

OdometryOptions LoadOdometryOptions(OptionsReader reader) {
  OdometryOptions o;
  reader.Read<double>("stamp_tolerance_s", &o.stamp_tolerance_s, CheckNonNegative);
  reader.Read<double>("max_gap_s", &o.max_gap_s, CheckPositive);
  reader.Read<int>("buffer_size", &o.buffer_size, CheckPositiveInt);
  reader.RejectUnknownKeys();
  return o;
}

MapperOptions LoadMapperOptions(OptionsReader reader) {
  MapperOptions o;
  reader.Read<std::string>("method", &o.method);
  o.ipm = LoadIpmOptions(reader.Child("ipm"));
  o.sanity = LoadMaskSanityOptions(reader.Child("sanity"));
  o.extraction = LoadExtractionOptions(reader.Child("extraction"));
  o.association = LoadAssociationOptions(reader.Child("association"));
  o.lanes = LoadLaneOptions(reader.Child("lanes"));
  o.odometry = LoadOdometryOptions(reader.Child("odometry"));
  o.input = LoadInputOptions(reader.Child("input"));
  o.backend = LoadBackendOptions(reader.Child("backend"));
  reader.RejectUnknownKeys();
  return o;
}

MapperOptions LoadMapperOptionsFile(const std::string& path) {
  try {
    return LoadMapperOptions(OptionsReader::FromFile(path));
  } catch (const OptionsError& e) {
    const std::string what = e.what();
    // FromFile already names the file; prefix it for errors found in the content.
    throw OptionsError(what.rfind(path, 0) == 0 ? what : path + ": " + what);
  }
}

AssociationOptions EffectiveAssociationOptions(const MapperOptions& options) {
  AssociationOptions association = options.association;
  association.odometry_sigma_m = options.backend.pose_prior_sigma_trans_m.head<2>().maxCoeff();
  return association;
}

std::string ToString(const MapperOptions& o) {
  std::ostringstream s;
  s << "method: " << o.method << "\n"
    << "ipm.max_range_m: " << o.ipm.max_range_m << "\n"
    << "ipm.pixel_error_px: [" << o.ipm.error_model.pixel_error_px.x() << ", "
    << o.ipm.error_model.pixel_error_px.y() << "]\n"
    << "ipm.pitch_sigma_deg: " << o.ipm.error_model.pitch_sigma_rad / kDegToRad << "\n"
    << "ipm.height_sigma_m: " << o.ipm.error_model.height_sigma_m << "\n"
    << "ipm.ground: " << ToString(o.ipm.ground) << "\n"
    << "ipm.road_grade_length_m: " << o.ipm.road_plane.grade_length_m << "\n"
    << "ipm.road_cross_slope_window_s: " << o.ipm.road_plane.cross_slope_window_s << "\n"
    << "lanes.point_selection: " << (o.lanes.point_selection ? "true" : "false") << "\n"
    << "lanes.selected_points_per_frame: " << o.lanes.selected_points_per_frame << "\n"
    << "lanes.chord_spacing_m: " << o.lanes.fit.chord_spacing_m << "\n"
    << "association.marking_gate_sigmas: " << o.association.marking_gate_sigmas << "\n"
    << "association.marking_position_sigma_m: " << o.association.marking_position_sigma_m << "\n"
    << "association.lane_max_point_score_m2: " << o.association.lane_max_point_score_m2 << "\n"
    << "association.lane_gate_m: " << o.association.lane_gate_m << "\n";
  const AssociationOptions gates = EffectiveAssociationOptions(o);
  s << "association floors (with the odometry's " << gates.odometry_sigma_m << " m): marking "
    << MarkingFloorSigma(gates) << " m, lane " << LaneFloorSigma(gates) << " m\n";
  s << ToString(o.backend);
  return s.str();
}

}  // namespace ipm_road_mapper
