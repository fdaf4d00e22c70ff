#include "ipm_road_mapper/core/mapper_options.h"

#include <cmath>
#include <sstream>
#include <vector>

namespace ipm_road_mapper {
namespace {
constexpr double kDegToRad = M_PI / 180.0;
}

IpmOptions LoadIpmOptions(OptionsReader reader) {
  IpmOptions o;
  reader.Read<double>("max_range_m", &o.max_range_m, CheckPositive);
  std::vector<double> pixel_error{o.error_model.pixel_error_px.x(),
                                  o.error_model.pixel_error_px.y()};
  reader.Read<std::vector<double>>("pixel_error_px", &pixel_error,
                                   [](const std::vector<double>& v) -> std::string {
                                     if (v.size() != 2) return "must be [du, dv]";
                                     if (!std::isfinite(v[0]) || !std::isfinite(v[1])) {
                                       return "must be finite";
                                     }
                                     return "";
                                   });
  o.error_model.pixel_error_px = {pixel_error[0], pixel_error[1]};
  double pitch_sigma_deg = o.error_model.pitch_sigma_rad / kDegToRad;
  reader.Read<double>("pitch_sigma_deg", &pitch_sigma_deg, CheckNonNegative);
  o.error_model.pitch_sigma_rad = pitch_sigma_deg * kDegToRad;
  reader.Read<double>("height_sigma_m", &o.error_model.height_sigma_m, CheckNonNegative);
  reader.RejectUnknownKeys();
  return o;
}

MapperOptions LoadMapperOptions(OptionsReader reader) {
  MapperOptions o;
  o.ipm = LoadIpmOptions(reader.Child("ipm"));
  reader.RejectUnknownKeys();
  return o;
}

std::string ToString(const MapperOptions& o) {
  std::ostringstream s;
  s << "ipm.max_range_m: " << o.ipm.max_range_m << "\n"
    << "ipm.pixel_error_px: [" << o.ipm.error_model.pixel_error_px.x() << ", "
    << o.ipm.error_model.pixel_error_px.y() << "]\n"
    << "ipm.pitch_sigma_deg: " << o.ipm.error_model.pitch_sigma_rad / kDegToRad << "\n"
    << "ipm.height_sigma_m: " << o.ipm.error_model.height_sigma_m << "\n";
  return s.str();
}

}  // namespace ipm_road_mapper
