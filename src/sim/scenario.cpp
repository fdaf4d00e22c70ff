#include "ipm_road_mapper/sim/scenario.h"

#include <cmath>
#include <functional>
#include <string>
#include <vector>

namespace ipm_road_mapper {
namespace sim {
namespace {

std::string CheckFinite(const double& v) { return std::isfinite(v) ? "" : "must be finite"; }
std::string CheckNonNegativeInt(const int& v) { return v >= 0 ? "" : "must be >= 0"; }

// Calls `parse` for every map of the sequence at `key` (absent: nothing).
void ForEachEntry(OptionsReader* reader, const std::string& key,
                  const std::function<void(OptionsReader*)>& parse) {
  const YAML::Node list = reader->Raw(key);
  if (!list || list.IsNull()) return;
  if (!list.IsSequence()) throw OptionsError(reader->KeyPath(key) + ": must be a list");
  for (std::size_t i = 0; i < list.size(); ++i) {
    OptionsReader entry(list[i], reader->KeyPath(key) + "[" + std::to_string(i) + "]");
    parse(&entry);
    entry.RejectUnknownKeys();
  }
}

const ClassInfo& ResolveClass(const ClassTable& classes, const std::string& name, ElementKind kind,
                              const std::string& key_path) {
  const ClassInfo* info = classes.FindByName(name);
  if (!info) throw OptionsError(key_path + ": unknown class '" + name + "'");
  if (info->kind != kind) {
    throw OptionsError(key_path + ": class '" + name + "' is a " + ToString(info->kind) +
                       " class, expected a " + ToString(kind) + " class");
  }
  return *info;
}

void ParseSurface(OptionsReader r, SurfaceOptions* o) {
  ForEachEntry(&r, "grade", [&](OptionsReader* e) {
    GradeKnot k;
    e->ReadRequired<double>("s_m", &k.s_m, CheckFinite);
    e->ReadRequired<double>("grade_pct", &k.grade_pct, [](const double& g) -> std::string {
      return std::abs(g) <= 20.0 ? "" : "must be within +-20 %";
    });
    if (!o->grade.empty() && k.s_m <= o->grade.back().s_m) {
      throw OptionsError(e->KeyPath("s_m") + ": knots must be in increasing s");
    }
    o->grade.push_back(k);
  });
  r.Read<double>("cross_slope_pct", &o->cross_slope_pct, CheckFinite);
  r.Read<double>("crown_pct", &o->crown_pct, [](const double& c) -> std::string {
    return c >= 0.0 && c <= 10.0 ? "" : "must be within 0-10 %";
  });
  r.Read<double>("crown_offset_m", &o->crown_offset_m, CheckFinite);
  ForEachEntry(&r, "waves", [&](OptionsReader* e) {
    SurfaceWave w;
    e->ReadRequired<double>("amplitude_m", &w.amplitude_m, CheckNonNegative);
    e->ReadRequired<double>("wavelength_m", &w.wavelength_m, CheckPositive);
    e->Read<double>("phase_deg", &w.phase_deg, CheckFinite);
    o->waves.push_back(w);
  });
  ForEachEntry(&r, "bumps", [&](OptionsReader* e) {
    SurfaceBump b;
    e->ReadRequired<double>("s_m", &b.s_m, CheckFinite);
    e->ReadRequired<double>("height_m", &b.height_m, CheckFinite);
    e->Read<double>("length_m", &b.length_m, CheckPositive);
    o->bumps.push_back(b);
  });
  r.RejectUnknownKeys();
}

void ParseRoad(OptionsReader r, const ClassTable& classes, RoadOptions* o) {
  ForEachEntry(&r, "segments", [&](OptionsReader* e) {
    RoadSegmentOptions seg;
    std::string type;
    e->ReadRequired<std::string>("type", &type);
    if (type == "straight") {
      e->ReadRequired<double>("length_m", &seg.length_m, CheckPositive);
    } else if (type == "arc") {
      seg.is_arc = true;
      e->ReadRequired<double>("radius_m", &seg.radius_m, CheckPositive);
      e->ReadRequired<double>("angle_deg", &seg.angle_deg, [](const double& a) -> std::string {
        return std::isfinite(a) && a != 0.0 && std::abs(a) < 360.0 ? ""
                                                                   : "must be in (-360, 360), != 0";
      });
      seg.length_m = seg.radius_m * std::abs(seg.angle_deg) * M_PI / 180.0;
    } else {
      throw OptionsError(e->KeyPath("type") + ": unknown segment type '" + type +
                         "' (straight or arc)");
    }
    o->segments.push_back(seg);
  });
  if (o->segments.empty()) throw OptionsError(r.KeyPath("segments") + ": needs >= 1 segment");
  r.Read<int>("lanes", &o->lanes, CheckPositiveInt);
  r.Read<double>("lane_width_m", &o->lane_width_m, CheckPositive);
  r.Read<double>("shoulder_width_m", &o->shoulder_width_m, CheckNonNegative);
  r.Read<double>("line_width_m", &o->line_width_m, CheckPositive);
  r.Read<double>("dash_length_m", &o->dash_length_m, CheckPositive);
  r.Read<double>("gap_length_m", &o->gap_length_m, CheckPositive);
  r.Read<double>("piece_length_m", &o->piece_length_m, CheckPositive);
  r.Read<std::vector<std::string>>("line_classes", &o->line_classes);
  if (o->line_classes.empty()) {
    for (int i = 0; i <= o->lanes; ++i) {
      o->line_classes.push_back(i == 0 || i == o->lanes ? "lane_white_solid" : "lane_white_dashed");
    }
  } else if (static_cast<int>(o->line_classes.size()) != o->lanes + 1) {
    throw OptionsError(r.KeyPath("line_classes") + ": needs lanes + 1 = " +
                       std::to_string(o->lanes + 1) + " entries (right to left)");
  }
  for (std::size_t i = 0; i < o->line_classes.size(); ++i) {
    const std::string key = r.KeyPath("line_classes") + "[" + std::to_string(i) + "]";
    o->line_class_ids.push_back(
        ResolveClass(classes, o->line_classes[i], ElementKind::kLane, key).id);
  }
  ParseSurface(r.Child("surface"), &o->surface);
  r.RejectUnknownKeys();
}

void ParseMarking(OptionsReader* e, const ClassTable& classes, int lanes, MarkingPlacement* m) {
  e->ReadRequired<std::string>("class", &m->class_name);
  m->class_id = ResolveClass(classes, m->class_name, ElementKind::kMarking, e->KeyPath("class")).id;
  e->ReadRequired<double>("s_m", &m->s_m, CheckFinite);
  e->Read<std::vector<int>>("lanes", &m->lanes, [lanes](const std::vector<int>& v) {
    for (int lane : v) {
      if (lane < 0 || lane >= lanes)
        return "lane " + std::to_string(lane) + " not in 0.." + std::to_string(lanes - 1);
    }
    return v.empty() ? std::string("must not be empty") : std::string();
  });
  m->has_offset = e->Has("offset_m");
  e->Read<double>("offset_m", &m->offset_m, CheckFinite);
  e->Read<double>("length_m", &m->length_m, CheckPositive);
  e->Read<double>("width_m", &m->width_m, CheckPositive);
  e->Read<double>("heading_deg", &m->heading_deg, CheckFinite);
  e->Read<std::string>("text", &m->text, [](const std::string& t) -> std::string {
    if (t.empty()) return "must not be empty";
    for (char c : t) {
      if (c < '0' || c > '9') return "only digits can be painted";
    }
    return "";
  });
  e->Read<int>("count_along", &m->count_along, CheckPositiveInt);
  e->Read<double>("step_along_m", &m->step_along_m, CheckPositive);
  e->Read<int>("count_across", &m->count_across, CheckPositiveInt);
  e->Read<double>("step_across_m", &m->step_across_m, CheckPositive);
}

void ParseVehicle(OptionsReader r, int lanes, VehicleOptions* o) {
  r.Read<int>("lane", &o->lane, [lanes](const int& v) -> std::string {
    return v >= 0 && v < lanes ? "" : "must be in 0.." + std::to_string(lanes - 1);
  });
  r.Read<double>("speed_mps", &o->speed_mps, CheckPositive);
  r.Read<double>("start_s_m", &o->start_s_m, CheckNonNegative);
  r.Read<double>("end_s_m", &o->end_s_m, CheckFinite);
  r.Read<double>("wheelbase_m", &o->wheelbase_m, CheckPositive);
  r.Read<double>("track_m", &o->track_m, CheckPositive);
  r.Read<double>("pitch_amplitude_deg", &o->pitch_amplitude_deg, CheckNonNegative);
  r.Read<double>("pitch_frequency_hz", &o->pitch_frequency_hz, CheckNonNegative);
  r.Read<double>("roll_amplitude_deg", &o->roll_amplitude_deg, CheckNonNegative);
  r.Read<double>("roll_frequency_hz", &o->roll_frequency_hz, CheckNonNegative);
  r.Read<double>("heave_amplitude_m", &o->heave_amplitude_m, CheckNonNegative);
  r.Read<double>("heave_frequency_hz", &o->heave_frequency_hz, CheckNonNegative);
  r.Read<double>("wander_amplitude_m", &o->wander_amplitude_m, CheckNonNegative);
  r.Read<double>("wander_period_s", &o->wander_period_s, CheckPositive);
  r.RejectUnknownKeys();
}

void ParseMount(OptionsReader r, CameraMount* m) {
  for (auto [key, value] : {std::pair<const char*, double*>{"x_m", &m->x_m},
                            {"y_m", &m->y_m},
                            {"z_m", &m->z_m},
                            {"roll_deg", &m->roll_deg},
                            {"pitch_deg", &m->pitch_deg},
                            {"yaw_deg", &m->yaw_deg}}) {
    r.Read<double>(key, value, CheckFinite);
  }
  r.RejectUnknownKeys();
}

void ParseCamera(OptionsReader r, CameraOptions* o) {
  CameraIntrinsics& in = o->intrinsics;
  r.Read<int>("width", &in.width, CheckPositiveInt);
  r.Read<int>("height", &in.height, CheckPositiveInt);
  in.cx = 0.5 * (in.width - 1);  // defaults follow the size
  in.cy = 0.5 * (in.height - 1);
  r.Read<double>("fx", &in.fx, CheckPositive);
  r.Read<double>("fy", &in.fy, CheckPositive);
  r.Read<double>("cx", &in.cx, CheckFinite);
  r.Read<double>("cy", &in.cy, CheckFinite);
  std::vector<double> d(in.distortion.begin(), in.distortion.end());
  r.Read<std::vector<double>>("distortion", &d, [](const std::vector<double>& v) -> std::string {
    return v.size() == 5 ? "" : "needs 5 plumb_bob coefficients (k1 k2 p1 p2 k3)";
  });
  for (int i = 0; i < 5; ++i) in.distortion[i] = d[i];
  const std::string problem = PinholeCamera(in).Validate();
  if (!problem.empty()) throw OptionsError(r.path() + ": " + problem);
  r.Read<double>("rate_hz", &o->rate_hz, CheckPositive);
  r.Read<std::string>("frame_id", &o->frame_id, [](const std::string& f) -> std::string {
    return f.empty() ? "must not be empty" : "";
  });
  ParseMount(r.Child("mount"), &o->mount);
  r.Read<double>("near_m", &o->near_m, CheckPositive);
  r.Read<double>("image_range_m", &o->image_range_m, CheckPositive);
  r.Read<int>("image_every_n_frames", &o->image_every_n_frames, CheckNonNegativeInt);
  r.RejectUnknownKeys();
}

void ParseRough(OptionsReader r, RoughExtrinsicOptions* o) {
  for (auto [key, value] : {std::pair<const char*, double*>{"roll_deg", &o->roll_deg},
                            {"pitch_deg", &o->pitch_deg},
                            {"yaw_deg", &o->yaw_deg},
                            {"x_m", &o->x_m},
                            {"y_m", &o->y_m},
                            {"z_m", &o->z_m}}) {
    r.Read<double>(key, value, CheckFinite);
  }
  r.RejectUnknownKeys();
}

void ParseOdometry(OptionsReader r, OdometryOptions* o) {
  r.Read<double>("rate_hz", &o->rate_hz, CheckPositive);
  r.Read<double>("xy_std_m", &o->xy_std_m, CheckNonNegative);
  r.Read<double>("yaw_std_deg", &o->yaw_std_deg, CheckNonNegative);
  r.Read<double>("correlation_time_s", &o->correlation_time_s, CheckPositive);
  r.Read<double>("jitter_xy_m", &o->jitter_xy_m, CheckNonNegative);
  r.Read<double>("jitter_yaw_deg", &o->jitter_yaw_deg, CheckNonNegative);
  r.Read<double>("time_offset_s", &o->time_offset_s, CheckNonNegative);
  r.RejectUnknownKeys();
}

void ParseSegmentation(OptionsReader r, SegmentationNoiseOptions* o) {
  r.Read<double>("boundary_jitter_px", &o->boundary_jitter_px, CheckNonNegative);
  r.Read<double>("jitter_wavelength_px", &o->jitter_wavelength_px, CheckPositive);
  r.Read<double>("missed_instance_prob", &o->missed_instance_prob, CheckProbability);
  r.Read<double>("spurious_blobs_per_frame", &o->spurious_blobs_per_frame, CheckNonNegative);
  r.Read<double>("range_m", &o->range_m, CheckPositive);
  r.Read<int>("min_instance_pixels", &o->min_instance_pixels, CheckNonNegativeInt);
  r.Read<double>("split_instance_prob", &o->split_instance_prob, CheckProbability);
  r.Read<int>("occluder_class_id", &o->occluder_class_id, [](const int& v) -> std::string {
    return v >= 0 && v <= kMaxClassId
               ? ""
               : "must be 0 (background) or a class id in 1.." + std::to_string(kMaxClassId);
  });
  std::string rasterizer =
      o->mask_rasterizer == FillRule::kPixelCenters ? "pixel_centers" : "opencv_fill_poly";
  r.Read<std::string>("mask_rasterizer", &rasterizer, [](const std::string& v) {
    return v == "opencv_fill_poly" || v == "pixel_centers"
               ? std::string()
               : std::string("must be opencv_fill_poly or pixel_centers");
  });
  o->mask_rasterizer =
      rasterizer == "pixel_centers" ? FillRule::kPixelCenters : FillRule::kOpenCvFillPoly;
  r.RejectUnknownKeys();
}

void ParseOccluder(OptionsReader* e, int lanes, OccluderOptions* o) {
  e->Read<int>("lane", &o->lane, [lanes](const int& v) -> std::string {
    return v >= 0 && v < lanes ? "" : "must be in 0.." + std::to_string(lanes - 1);
  });
  o->has_offset = e->Has("offset_m");
  e->Read<double>("offset_m", &o->offset_m, CheckFinite);
  e->Read<double>("gap_m", &o->gap_m, CheckPositive);
  e->Read<double>("gap_amplitude_m", &o->gap_amplitude_m, CheckNonNegative);
  e->Read<double>("gap_period_s", &o->gap_period_s, CheckPositive);
  e->Read<double>("start_s_m", &o->start_s_m, CheckFinite);
  e->Read<double>("end_s_m", &o->end_s_m, CheckFinite);
  e->Read<double>("length_m", &o->length_m, CheckPositive);
  e->Read<double>("width_m", &o->width_m, CheckPositive);
  e->Read<double>("height_m", &o->height_m, CheckPositive);
  if (o->gap_amplitude_m >= o->gap_m) {
    throw OptionsError(e->KeyPath("gap_amplitude_m") +
                       ": must be < gap_m (the vehicle ahead "
                       "would reach the camera)");
  }
}

}  // namespace

CameraIntrinsics DefaultIntrinsics() {
  CameraIntrinsics in;
  in.width = 1280;
  in.height = 720;
  in.fx = in.fy = 1000.0;
  in.cx = 639.5;
  in.cy = 359.5;
  in.distortion = {{-0.05, 0.01, 0.0, 0.0, 0.0}};
  return in;
}

ScenarioOptions LoadScenario(OptionsReader reader, const ClassTable& classes) {
  ScenarioOptions o;
  o.camera.intrinsics = DefaultIntrinsics();
  reader.ReadRequired<std::string>("name", &o.name);
  reader.Read<double>("start_time_s", &o.start_time_s, CheckPositive);
  ParseRoad(reader.Child("road"), classes, &o.road);
  ForEachEntry(&reader, "markings", [&](OptionsReader* e) {
    MarkingPlacement m;
    ParseMarking(e, classes, o.road.lanes, &m);
    o.markings.push_back(m);
  });
  reader.Read<int>("repeat_count", &o.repeat_count, CheckPositiveInt);
  RepeatRoute(o.repeat_count, &o);
  ParseVehicle(reader.Child("vehicle"), o.road.lanes, &o.vehicle);
  ParseCamera(reader.Child("camera"), &o.camera);
  ParseRough(reader.Child("rough_extrinsic"), &o.rough_extrinsic);
  ParseOdometry(reader.Child("odometry"), &o.odometry);
  ParseSegmentation(reader.Child("segmentation"), &o.segmentation);
  ForEachEntry(&reader, "occluders", [&](OptionsReader* e) {
    OccluderOptions occluder;
    ParseOccluder(e, o.road.lanes, &occluder);
    o.occluders.push_back(occluder);
  });
  OptionsReader check = reader.Child("ipm_check");
  check.Read<double>("max_distance_m", &o.ipm_check.max_distance_m, CheckPositive);
  check.RejectUnknownKeys();
  reader.RejectUnknownKeys();

  double road_length = 0.0;
  for (const auto& seg : o.road.segments) road_length += seg.length_m;
  if (o.vehicle.end_s_m < 0.0) o.vehicle.end_s_m = road_length - 10.0;
  if (o.vehicle.end_s_m <= o.vehicle.start_s_m) {
    throw OptionsError("vehicle.end_s_m: must be > vehicle.start_s_m (road is " +
                       std::to_string(road_length) + " m long)");
  }
  if (o.camera.mount.z_m <= 0.0) throw OptionsError("camera.mount.z_m: must be > 0");
  for (OccluderOptions& occluder : o.occluders) {
    if (occluder.end_s_m < 0.0) occluder.end_s_m = road_length;
  }
  return o;
}

ScenarioOptions LoadScenarioFile(const std::string& path, const ClassTable& classes) {
  OptionsReader reader = OptionsReader::FromFile(path);  // its errors name the file
  try {
    return LoadScenario(reader, classes);
  } catch (const OptionsError& e) {
    throw OptionsError(path + ": " + e.what());
  }
}

}  // namespace sim
}  // namespace ipm_road_mapper
