// Scenario of a synthetic drive (config/scenarios/*.yaml): road geometry and surface,
// markings, vehicle motion, camera, the rough extrinsic handed to the mapper, odometry and
// segmentation noise. Loaded with OptionsReader, so an unknown key, a bad value or an
// unknown class name is an OptionsError naming the key path. docs/synthetic_drives.md
// lists every key with its unit and default.
#pragma once

#include <string>
#include <vector>

#include "ipm_road_mapper/core/frontend/class_table.h"
#include "ipm_road_mapper/core/geometry/pinhole_camera.h"
#include "ipm_road_mapper/core/io/yaml_options.h"
#include "ipm_road_mapper/sim/fill_rule.h"

namespace ipm_road_mapper {
namespace sim {

// One piece of the road's centerline: a straight or a circular arc (left turn for a
// positive angle).
struct RoadSegmentOptions {
  bool is_arc = false;
  double length_m = 0.0;   // straight only
  double radius_m = 0.0;   // arc only
  double angle_deg = 0.0;  // arc only; > 0 turns left
};

// A knot of the grade profile: the grade is linear in s between knots (a parabolic
// vertical curve, so the height is C1) and constant outside them.
struct GradeKnot {
  double s_m = 0.0;
  double grade_pct = 0.0;
};

// A sinusoidal undulation of the surface along the road: A sin(2 pi s / lambda + phase).
struct SurfaceWave {
  double amplitude_m = 0.0;
  double wavelength_m = 10.0;
  double phase_deg = 0.0;
};

// A Gaussian bump across the whole road width: h exp(-(s - s0)^2 / (2 sigma^2)) with
// sigma = length_m / 4 (so length_m spans +-2 sigma).
struct SurfaceBump {
  double s_m = 0.0;
  double height_m = 0.0;
  double length_m = 2.0;
};

// Road surface height z(s, l) = grade integral + cross slope * l - crown * |l - l_crown|
// + waves + bumps. The crown makes the road a roof across: two planes meeting at a ridge
// line (a real carriageway falls to both gutters from its centre line, 1.5-2.5 % each way),
// so a vehicle on one side rests on that side's plane and the lines beyond the ridge lie
// below it.
struct SurfaceOptions {
  std::vector<GradeKnot> grade;  // empty: flat profile
  double cross_slope_pct = 0.0;  // > 0: the left side (l > 0) is higher
  double crown_pct = 0.0;        // > 0: the surface falls this steeply away from the ridge
  double crown_offset_m = 0.0;   // the ridge's lateral offset l_crown (0: the centerline)
  std::vector<SurfaceWave> waves;
  std::vector<SurfaceBump> bumps;
};

// Road layout. Lanes are numbered from the right (lane 0 = rightmost) and the centerline
// (s axis) runs through the middle of the carriageway; l is the lateral offset, left > 0.
struct RoadOptions {
  std::vector<RoadSegmentOptions> segments;
  int lanes = 3;
  double lane_width_m = 3.5;
  double shoulder_width_m = 1.0;  // rendered in the image only
  double line_width_m = 0.15;
  double dash_length_m = 3.0;
  double gap_length_m = 6.0;
  double piece_length_m = 0.75;  // lane lines are rendered as surface quads this long
  // Class of each lane line from right to left (lanes + 1 entries); its style (solid or
  // dashed) comes from the class table. Default: outer lines lane_white_solid, inner lines
  // lane_white_dashed.
  std::vector<std::string> line_classes;
  std::vector<int> line_class_ids;  // resolved from line_classes
  SurfaceOptions surface;
};

// A marking, or a grid of equal markings (count_along x count_across), placed on the road.
struct MarkingPlacement {
  std::string class_name;
  int class_id = 0;
  double s_m = 0.0;           // center of the first marking along the road
  std::vector<int> lanes{0};  // one placement per lane (lane centers) ...
  bool has_offset = false;    // ... unless offset_m is given (lateral offset, left > 0)
  double offset_m = 0.0;
  double length_m = 5.0;       // along the marking's heading (the road direction)
  double width_m = 1.0;        // across it
  double heading_deg = 0.0;    // rotation from the road direction, counter-clockwise
  std::string text = "60";     // speed_limit only: the digits painted
  int count_along = 1;         // repetitions forward along the road ...
  double step_along_m = 10.0;  // ... this far apart (first at s_m)
  int count_across = 1;        // repetitions across the road, centered on the lane/offset
  double step_across_m = 1.0;
};

// Vehicle motion: drives along a lane center at constant speed; the body pitches and
// heaves on its suspension (sinusoids with seed-dependent phases).
struct VehicleOptions {
  int lane = 1;
  double speed_mps = 10.0;
  double start_s_m = 5.0;
  double end_s_m = -1.0;     // < 0: road length - 10 m
  double wheelbase_m = 2.8;  // road pitch = slope between the axles
  double track_m = 1.6;      // road roll = slope between the wheels
  double pitch_amplitude_deg = 0.3;
  double pitch_frequency_hz = 1.1;
  double roll_amplitude_deg = 0.1;
  double roll_frequency_hz = 0.7;
  double heave_amplitude_m = 0.01;
  double heave_frequency_hz = 1.5;
  double wander_amplitude_m = 0.15;  // slow lateral weaving within the lane
  double wander_period_s = 14.0;
};

// A camera pose on the vehicle: position in base_link and mounting angles. The optical
// frame is the mount frame (x forward, y left, z up) turned to z forward, x right, y down;
// the mount is rotated by R = Rz(yaw) Ry(pitch) Rx(roll), so pitch_deg > 0 looks down.
struct CameraMount {
  double x_m = 1.5, y_m = 0.0, z_m = 1.5;
  double roll_deg = 0.0, pitch_deg = 4.0, yaw_deg = 0.0;
};

// The camera: intrinsics, frame rate, the true mount and the rendering options.
struct CameraOptions {
  CameraIntrinsics intrinsics;  // defaults set in the loader (1280x720, fx = fy = 1000)
  double rate_hz = 20.0;
  std::string frame_id = "camera_optical";
  CameraMount mount;
  double near_m = 0.2;           // near clipping plane (depth along the optical axis)
  double image_range_m = 120.0;  // the gray image shows the road this far (depth)
  int image_every_n_frames = 1;  // publish /camera/image_raw every Nth frame
};

// The rough extrinsic handed to the mapper: the true mount plus these offsets.
struct RoughExtrinsicOptions {
  double roll_deg = 0.0, pitch_deg = 0.0, yaw_deg = 0.0;
  double x_m = 0.0, y_m = 0.0, z_m = 0.0;
};

// Odometry: true pose plus per-axis Ornstein-Uhlenbeck errors on x, y (map frame) and yaw,
// with stationary standard deviations *_std and correlation time tau, plus white jitter.
struct OdometryOptions {
  double rate_hz = 50.0;
  double xy_std_m = 0.2;
  double yaw_std_deg = 0.2;
  double correlation_time_s = 4.0;
  double jitter_xy_m = 0.005;
  double jitter_yaw_deg = 0.01;
  double time_offset_s = 0.0037;  // first odometry stamp after the first camera stamp - 0.1 s
};

// Segmentation noise applied to the instance masks (the image is noise-free).
struct SegmentationNoiseOptions {
  double boundary_jitter_px = 0.8;     // amplitude of a smooth per-frame displacement field
  double jitter_wavelength_px = 40.0;  // its spatial wavelength
  double missed_instance_prob = 0.02;
  double spurious_blobs_per_frame = 0.2;  // Poisson mean
  double range_m = 40.0;                  // nothing deeper than this is rendered in the mask
  int min_instance_pixels = 12;           // smaller instances are erased
  // Per frame, each lane or marking instance is cut in two along a random line through its
  // pixel centroid with this probability; the second part gets a fresh instance index.
  double split_instance_prob = 0.0;
  // The class the segmentation gives the vehicles ahead (OccluderOptions): 0 draws them as
  // background, as a network that segments road paint only would; 1..65 draws each as an
  // instance of that class (class_id * 1000 + occluder index + 1), as a panoptic one would.
  int occluder_class_id = 0;
  // How the mask's polygons become pixels (fill_rule.h; YAML "opencv_fill_poly", the default,
  // which the benchmark's figures were measured on, or "pixel_centers").
  FillRule mask_rasterizer = FillRule::kOpenCvFillPoly;
};

// A vehicle driving ahead of the ego vehicle; its box hides the road behind it (drawn as
// background, value 0, in the mask unless segmentation.occluder_class_id is set, and dark in
// the image). Its rear is gap(t) = gap_m +
// gap_amplitude_m sin(2 pi t / gap_period_s) ahead of the camera along the road (t from
// the first frame), on a lane center or a lateral offset, heading along the road.
struct OccluderOptions {
  int lane = 1;             // drives this lane's center ...
  bool has_offset = false;  // ... unless offset_m is given (lateral offset, left > 0)
  double offset_m = 0.0;
  double gap_m = 12.0;
  double gap_amplitude_m = 0.0;
  double gap_period_s = 20.0;
  double start_s_m = 0.0;  // present while its rear is within [start_s_m, end_s_m] ...
  double end_s_m = -1.0;   // ... (< 0: the road's length)
  double length_m = 4.5, width_m = 1.8, height_m = 1.5;
};

// The plain-IPM error check of the generator (see ipm_check.h).
struct IpmCheckOptions {
  double max_distance_m = 25.0;
};

// A complete, validated scenario.
struct ScenarioOptions {
  std::string name;
  double start_time_s = 1000.0;  // stamp of the first camera frame
  int repeat_count = 1;          // the route (road + markings) laid end to end this many times
  RoadOptions road;
  std::vector<MarkingPlacement> markings;
  VehicleOptions vehicle;
  CameraOptions camera;
  RoughExtrinsicOptions rough_extrinsic;
  OdometryOptions odometry;
  SegmentationNoiseOptions segmentation;
  std::vector<OccluderOptions> occluders;  // vehicles ahead
  IpmCheckOptions ipm_check;
};

// Reads and validates a scenario; class names are resolved against `classes`. Throws
// OptionsError naming the key path on any problem.
ScenarioOptions LoadScenario(OptionsReader reader, const ClassTable& classes);

// Lays the route `count` times end to end (long drives): copy k of the road segments, grade
// knots, bumps and marking placements is shifted by k times the road length; waves are
// functions of s and stay as they are. Throws OptionsError when the grade knots span the
// road's whole length (the shifted copies would not be in increasing s).
void RepeatRoute(int count, ScenarioOptions* scenario);

// Same, from a file; the error message starts with the file path.
ScenarioOptions LoadScenarioFile(const std::string& path, const ClassTable& classes);

// The default camera intrinsics (1280x720, fx = fy = 1000, mild barrel distortion).
CameraIntrinsics DefaultIntrinsics();

}  // namespace sim
}  // namespace ipm_road_mapper
