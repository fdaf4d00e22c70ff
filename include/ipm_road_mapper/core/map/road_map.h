// The mapper's working map: elements with their observation histories (what the back end
// optimizes over) and the frames that observed them. VectorMap (vector_map.h) is the
// exported view of it.
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "ipm_road_mapper/core/frontend/observations.h"
#include "ipm_road_mapper/core/geometry/road_surface.h"

namespace ipm_road_mapper {

// One frame the mapper used: its odometry pose, its current (corrected) pose and the ground
// its front end mapped pixels onto.
struct FrameRecord {
  std::size_t index = 0;  // position in RoadMap::frames
  double stamp = 0.0;
  Eigen::Isometry3d T_map_base_odom = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d T_map_base = Eigen::Isometry3d::Identity();  // corrected estimate
  RoadPlane ground_base;  // the front end's ground in base_link (trajectory_road_plane.h)
};

// One observation of a marking, corners already in the element's corner order.
struct MarkingMeasurement {
  std::size_t frame_index = 0;
  std::array<Eigen::Vector2d, 4> corners_uv;    // pixel measurements z_k (flat-ground IPM)
  std::array<Eigen::Vector3d, 4> corners_base;  // their IPM ground points at observation time
  // The instance's convex outline in the image: the back end re-measures the corners from
  // it on a better road plane than base_link's (MeasureCornersOnPlane).
  std::vector<Eigen::Vector2d> outline_uv;
  // Partial views (MarkingObservation): which sides (side i from corner i to i + 1) the view
  // measured, and the observed boundary pixels of each; a corner is a measurement only where
  // both of its sides are.
  std::array<bool, 4> side_measured{{true, true, true, true}};
  std::array<std::vector<Eigen::Vector2d>, 4> side_uv;
  bool CornerMeasured(int i) const { return side_measured[(i + 3) % 4] && side_measured[i]; }
  bool Complete() const {
    return side_measured[0] && side_measured[1] && side_measured[2] && side_measured[3];
  }
};

// A mapped ground marking.
struct MarkingElement {
  std::uint64_t id = 0;
  // MapStore::Touch's revision of the last change of what export shows (0: never touched).
  std::uint64_t revision = 0;
  int class_id = 0;
  std::array<Eigen::Vector3d, 4> corners_map;  // current estimate
  // x-y covariance of the estimate for association: Omega_p of the best observation (the
  // plain-IPM errors of one element's observations are correlated, so no 1/n).
  Eigen::Matrix2d center_cov_map = Eigen::Matrix2d::Zero();
  std::vector<MarkingMeasurement> history;  // sorted by frame; the oldest pruned (below)
  // Measurements pruned from the history (older than the final solve's horizon): counted,
  // not kept, so that memory grows with the map and not with the frames seen.
  std::size_t pruned = 0;
  std::size_t first_frame = 0, last_frame = 0;
  double first_seen = 0.0, last_seen = 0.0;
  bool optimized = false;  // the back end owns the estimate from now on
  bool retired = false;    // left the window: its information is in the extrinsic prior
  // Per side (side i from corner i to i + 1): some view saw the marking's boundary there.
  // An unmeasured side is where the views ended so far: the extent grows past it as later
  // views show more (a marking larger than the view), and the export says so.
  std::array<bool, 4> side_measured{{true, true, true, true}};
  // How many views measured each side (the running mean of its position).
  std::array<std::size_t, 4> side_views{{0, 0, 0, 0}};
  // Consistency with the road's motion (MarkingTracker::CheckConsistency): frames since
  // creation in which it should have been visible (its center in the image, no farther
  // than its farthest view) and those of them that saw it. A marking is confirmed once seen
  // in at least half the frames it was expected in (and twice); until then it is tentative:
  // not exported, not in the back end. A spurious blob is never seen again where it should.
  std::size_t frames_expected = 0;
  std::size_t frames_seen = 0;
  double farthest_view_m = 0.0;  // largest ground distance of a view's center from base_link
  bool confirmed = false;
  // Made by far views alone (ExtractionOptions::far_marking_range_m; docs/backend.md, "Far
  // views"): its estimate is the mean of their IPM weighted by 1 / tr(Omega_p) (far_weight:
  // the weights' sum), it never enters the back end, and the first near view restarts it
  // from that view. Where it came within max_marking_range_m with its center in the image,
  // a near view should have found it: near_frames_expected counts those frames.
  bool far_only = false;
  double far_weight = 0.0;
  std::size_t near_frames_expected = 0;
  // Every observation ever made, pruned ones included.
  std::size_t Observations() const { return history.size() + pruned; }
  // Whether export shows it: seen at least twice (seen once, it is tentative).
  bool Exported() const { return Observations() >= 2; }
  // The revision of the first Touch that found it Exported() (0: not yet): an incremental
  // export since an older revision sends it whole (the client never had it).
  std::uint64_t exported_at = 0;
  bool Complete() const {
    return side_measured[0] && side_measured[1] && side_measured[2] && side_measured[3];
  }
  Eigen::Vector3d Center() const {
    return 0.25 * (corners_map[0] + corners_map[1] + corners_map[2] + corners_map[3]);
  }
};

// One observation of a lane: its centerline points (pixels, ground, scores) and which of
// them point selection kept.
struct LaneMeasurement {
  std::size_t frame_index = 0;
  std::vector<LanePoint> points;
  std::vector<std::uint8_t> selected;  // 1 where PS kept the point (all 1 without PS)
  // The selected points in the map frame, with the pose and extrinsic of observation time
  // (what the growth of the lane's ends fits).
  std::vector<Eigen::Vector3d> selected_map;
};

// A mapped lane line.
struct LaneElement {
  std::uint64_t id = 0;
  // MapStore::Touch's revision of the last change of what export shows (0: never touched).
  std::uint64_t revision = 0;
  int class_id = 0;
  std::vector<Eigen::Vector3d> control_points_map;  // Catmull-Rom, phantom ends included
  // Global index of control_points_map[0]; decreases as the lane grows at its start, so
  // back-end results computed on an older copy can be applied point by point.
  std::int64_t first_cp_index = 0;
  std::vector<LaneMeasurement> history;  // sorted by frame; the oldest pruned (below)
  std::size_t pruned = 0;                // measurements pruned from the history
  std::size_t first_frame = 0, last_frame = 0;
  double first_seen = 0.0, last_seen = 0.0;
  bool optimized = false;  // control points refined by a lane residual
  // Control points a join laid across a gap in the line's observations (lane_unmeasured.h):
  // no pixel measured them. Inclusive ranges of global indices (first_cp_index's),
  // ascending and disjoint.
  std::vector<std::pair<std::int64_t, std::int64_t>> unmeasured_cps;
  // Every observation ever made, pruned ones included.
  std::size_t Observations() const { return history.size() + pruned; }
  // Whether export shows it: seen at least twice (seen once, it is tentative).
  bool Exported() const { return Observations() >= 2; }
  // The revision of the first Touch that found it Exported() (0: not yet): an incremental
  // export since an older revision sends it whole (the client never had it).
  std::uint64_t exported_at = 0;
  // Observations of frames before this one no longer enter windows.
  std::size_t retired_before_frame = 0;
};

// Elements and frames.
struct RoadMap {
  std::vector<FrameRecord> frames;
  // The live markings (observed within the window, or not yet moved out of it) and the
  // retired ones (left the window: their information is in the extrinsic prior).
  std::vector<MarkingElement> markings;
  std::vector<MarkingElement> retired_markings;
  std::vector<LaneElement> lanes;
  std::uint64_t next_id = 1;
};

}  // namespace ipm_road_mapper
