// Typed options of the mapper, loaded and validated in one place from YAML (the offline
// runner reads config/mapper.yaml directly; the nodelet converts its private parameters
// to the same YAML tree), so both share one schema. Angles are degrees in the file
// (`*_deg` keys) and radians here.
#pragma once

#include <string>

#include "ipm_road_mapper/core/backend/backend_options.h"
#include "ipm_road_mapper/core/frontend/association.h"
#include "ipm_road_mapper/core/frontend/instance_extraction.h"
#include "ipm_road_mapper/core/frontend/mask_sanity.h"
#include "ipm_road_mapper/core/geometry/ipm_uncertainty.h"
#include "ipm_road_mapper/core/geometry/lane_end_fit.h"
#include "ipm_road_mapper/core/geometry/spline_fitting.h"
#include "ipm_road_mapper/core/geometry/trajectory_road_plane.h"
#include "ipm_road_mapper/core/io/yaml_options.h"
#include "ipm_road_mapper/core/mapper/input_options.h"
#include "ipm_road_mapper/core/mapper/lane_join.h"

namespace ipm_road_mapper {

// What the front end's IPM maps pixels onto (config key `ipm.ground`).
enum class IpmGround {
  kTrajectory,  // the road under and ahead of the vehicle, from its trajectory
  kBaseLink,    // base_link's plane z = 0 (the paper's flat-ground IPM; pitches with the body)
};

// IPM and its error model.
struct IpmOptions {
  double max_range_m = 40.0;  // ground points farther than this are rejected
  IpmErrorModel error_model;  // Omega_p inputs (docs/design.md defaults)
  IpmGround ground = IpmGround::kBaseLink;
  TrajectoryRoadPlaneOptions road_plane;  // the trajectory's road plane (ground: trajectory)
};

// "trajectory" / "base_link".
const char* ToString(IpmGround ground);

// How lane lines become splines (config section `lanes`).
struct LaneOptions {
  bool point_selection = true;         // PS: keep only the lowest-uncertainty points per frame
  int selected_points_per_frame = 12;  // N of PS, per lane observation
  double max_selected_score_m2 = 1.0;  // PS also drops points with tr(Omega_p) above this
  SplineFitOptions fit;                // g: chord spacing etc. (starts a lane)
  LaneEndFitOptions end_fit;           // growth of a lane's ends (chord spacing = g's)
  int end_fit_frames = 20;             // the growth sees the selected points of this many frames
  // A lane's ends grow along the arc concentric with the driven path's curvature over this
  // length (heading change / distance); 0: straight along the last chord.
  double end_growth_path_length_m = 10.0;
  int merge_every_n_frames = 20;       // how often lanes that turned out to be one are merged
  double min_new_lane_length_m = 3.0;  // an unmatched observation shorter than this: no lane
  LaneJoinOptions join;                // joining the fragments of one line (lane_join.h)
};

// Odometry buffering at the mask stamp (config section `odometry`).
struct OdometryOptions {
  double stamp_tolerance_s = 0.05;  // a mask this far outside the odometry span is still ok
  double max_gap_s = 0.5;           // bracketing odometry farther apart: frame skipped
  int buffer_size = 2000;           // odometry messages kept for interpolation
};

// Everything the mapper is configured with.
struct MapperOptions {
  std::string method = "ipm";  // name of the configuration, e.g. ipm, ours_ppsr
  IpmOptions ipm;
  MaskSanityOptions sanity;  // the mask made sane before extraction (mask_sanity.h)
  ExtractionOptions extraction;
  AssociationOptions association;
  LaneOptions lanes;
  OdometryOptions odometry;
  InputOptions input;
  BackendOptions backend;
};

// Reads the `ipm` section; throws OptionsError naming the bad key.
IpmOptions LoadIpmOptions(OptionsReader reader);

// Reads the `lanes` section; throws OptionsError naming the bad key.
LaneOptions LoadLaneOptions(OptionsReader reader);

// Reads the `odometry` section; throws OptionsError naming the bad key.
OdometryOptions LoadOdometryOptions(OptionsReader reader);

// Reads a whole mapper config; unknown keys are errors. Throws OptionsError.
MapperOptions LoadMapperOptions(OptionsReader reader);

// Loads a mapper config file; errors are prefixed with the file path.
MapperOptions LoadMapperOptionsFile(const std::string& path);

// The association options as the Mapper uses them: odometry_sigma_m taken from
// backend.pose_prior_sigma_trans_m (x-y), so that the odometry's noise is stated once.
AssociationOptions EffectiveAssociationOptions(const MapperOptions& options);

// A multi-line, human-readable dump of the options (printed at start-up).
std::string ToString(const MapperOptions& options);

}  // namespace ipm_road_mapper
