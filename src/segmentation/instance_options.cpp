// LoadInstanceOptions: config/segmentation.yaml's `instances` section, every key validated.
#include <string>

#include "ipm_road_mapper/segmentation/paint_instancer.h"

namespace ipm_road_mapper {
namespace segmentation {
namespace {

std::string CheckUnitInterval(const double& v) {
  return v >= 0.0 && v <= 1.0 ? "" : "must be in [0, 1] (got " + std::to_string(v) + ")";
}

std::string CheckAngle(const double& v) {
  return v >= 0.0 && v <= 90.0 ? "" : "must be in [0, 90] deg (got " + std::to_string(v) + ")";
}

std::string CheckClassId(const int& v) {
  return v >= 1 && v <= 65 ? "" : "must be a class id in 1..65 (got " + std::to_string(v) + ")";
}

void LoadRaster(OptionsReader r, GroundRasterOptions* o) {
  r.Read<double>("cell_m", &o->cell_m, CheckPositive);
  r.Read<double>("min_ahead_m", &o->min_ahead_m, CheckNonNegative);
  r.Read<double>("max_ahead_m", &o->max_ahead_m, [o](const double& v) -> std::string {
    return v > o->min_ahead_m ? "" : "must be > min_ahead_m (got " + std::to_string(v) + ")";
  });
  r.Read<double>("half_width_m", &o->half_width_m, CheckPositive);
  r.RejectUnknownKeys();
  if ((o->max_ahead_m - o->min_ahead_m) * 2.0 * o->half_width_m / (o->cell_m * o->cell_m) > 4e6) {
    throw OptionsError(r.path() + ": more than 4 million cells; raise cell_m");
  }
}

void LoadPieces(OptionsReader r, PieceOptions* o) {
  r.Read<double>("orientation_scale_m", &o->orientation_scale_m, CheckPositive);
  r.Read<double>("min_coherence", &o->min_coherence, CheckUnitInterval);
  r.Read<double>("max_turn_deg", &o->max_turn_deg, CheckAngle);
  r.Read<double>("min_area_m2", &o->min_area_m2, CheckNonNegative);
  r.Read<double>("blob_core_radius_m", &o->blob_core_radius_m, CheckPositive);
  r.RejectUnknownKeys();
}

void LoadGroups(OptionsReader r, GroupOptions* o) {
  r.Read<double>("max_stroke_width_m", &o->max_stroke_width_m, CheckPositive);
  r.Read<double>("min_stroke_elongation", &o->min_stroke_elongation, CheckPositive);
  r.Read<double>("min_stroke_length_m", &o->min_stroke_length_m, CheckNonNegative);
  r.Read<double>("chain_max_gap_m", &o->chain_max_gap_m, CheckPositive);
  r.Read<double>("chain_max_turn_deg", &o->chain_max_turn_deg, CheckAngle);
  r.Read<double>("chain_max_offset_m", &o->chain_max_offset_m, CheckPositive);
  r.Read<double>("stack_max_turn_deg", &o->stack_max_turn_deg, CheckAngle);
  r.Read<double>("stack_min_spacing_m", &o->stack_min_spacing_m, CheckNonNegative);
  r.Read<double>("stack_max_spacing_m", &o->stack_max_spacing_m, CheckPositive);
  r.Read<double>("stack_min_overlap", &o->stack_min_overlap, CheckUnitInterval);
  r.RejectUnknownKeys();
}

void LoadClassify(OptionsReader r, ClassifyOptions* o) {
  r.Read<double>("max_line_width_m", &o->max_line_width_m, CheckPositive);
  r.Read<double>("line_blur_px", &o->line_blur_px, CheckNonNegative);
  r.Read<double>("min_line_span_m", &o->min_line_span_m, CheckNonNegative);
  r.Read<double>("max_dash_length_m", &o->max_dash_length_m, CheckPositive);
  r.Read<double>("min_dash_gap_m", &o->min_dash_gap_m, CheckNonNegative);
  r.Read<double>("crossing_max_turn_deg", &o->crossing_max_turn_deg, CheckAngle);
  r.Read<double>("crossing_max_spacing_m", &o->crossing_max_spacing_m, CheckPositive);
  r.Read<double>("area_margin_m", &o->area_margin_m, CheckNonNegative);
  r.Read<double>("stop_line_min_turn_deg", &o->stop_line_min_turn_deg, CheckAngle);
  r.Read<double>("stop_line_min_length_m", &o->stop_line_min_length_m, CheckPositive);
  r.Read<double>("stop_line_max_width_m", &o->stop_line_max_width_m, CheckPositive);
  r.Read<double>("arrow_max_turn_deg", &o->arrow_max_turn_deg, CheckAngle);
  r.Read<double>("arrow_min_length_m", &o->arrow_min_length_m, CheckPositive);
  r.Read<double>("arrow_max_length_m", &o->arrow_max_length_m, CheckPositive);
  r.Read<double>("arrow_max_width_m", &o->arrow_max_width_m, CheckPositive);
  r.Read<double>("min_confidence", &o->min_confidence, CheckUnitInterval);
  r.RejectUnknownKeys();
}

void LoadClassIds(OptionsReader r, std::array<int, kPaintClassCount>* ids) {
  for (int c = 0; c < kPaintClassCount; ++c) {
    r.Read<int>(ToString(static_cast<PaintClass>(c)), &(*ids)[c], CheckClassId);
  }
  r.RejectUnknownKeys();
}

}  // namespace

InstanceOptions LoadInstanceOptions(OptionsReader reader) {
  InstanceOptions o;
  reader.Read<double>("paint_threshold", &o.paint_threshold, CheckUnitInterval);
  LoadRaster(reader.Child("raster"), &o.raster);
  LoadPieces(reader.Child("pieces"), &o.pieces);
  LoadGroups(reader.Child("groups"), &o.groups);
  LoadClassify(reader.Child("classes"), &o.classes);
  LoadClassIds(reader.Child("class_ids"), &o.class_ids);
  reader.RejectUnknownKeys();
  return o;
}

}  // namespace segmentation
}  // namespace ipm_road_mapper
