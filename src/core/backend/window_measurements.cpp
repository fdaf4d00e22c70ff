#include "ipm_road_mapper/core/backend/window_measurements.h"

#include <algorithm>
#include <optional>

#include "ipm_road_mapper/core/frontend/marking_measurement.h"
#include "ipm_road_mapper/core/geometry/catmull_rom_spline.h"
#include "ipm_road_mapper/core/geometry/ipm.h"
#include "ipm_road_mapper/core/geometry/road_surface.h"

namespace ipm_road_mapper {
namespace window_solve {

void CollectCornerMeasurements(const WindowSnapshot& snapshot, const BackendOptions& options,
                               WindowState* state) {
  const PinholeCamera camera(snapshot.camera);
  const Eigen::Isometry3d T_base_cam = state->extrinsic.ToIsometry();
  for (std::size_t m = 0; m < snapshot.markings.size(); ++m) {
    const auto& corners = state->corners[m];
    const Eigen::Vector3d center = 0.25 * (corners[0] + corners[1] + corners[2] + corners[3]);
    const RoadPlane plane =
        RoadSurfaceNear(state->poses, center, options.road_plane_radius_m).plane;
    const Eigen::Vector3d& axis = snapshot.markings[m].axis_map;
    const auto& measurements = snapshot.markings[m].measurements;
    // Partial views measure a marking no whole view shows (one larger than the view); where
    // whole views exist they alone are measurements (see docs/backend.md, "Partial views").
    const bool seen_whole =
        std::any_of(measurements.begin(), measurements.end(),
                    [](const MarkingMeasurement& meas) { return meas.Complete(); });
    std::vector<std::size_t> usable;
    for (std::size_t i = 0; i < measurements.size(); ++i) {
      if (!seen_whole || measurements[i].Complete()) usable.push_back(i);
    }
    // At most max_measurements_per_marking of them, spread over the history (the first and
    // the last included): neighbouring frames see a marking almost alike.
    const std::size_t cap = static_cast<std::size_t>(options.max_measurements_per_marking);
    std::vector<std::size_t> chosen;
    if (usable.size() <= cap) {
      chosen = usable;
    } else {
      for (std::size_t k = 0; k < cap; ++k) {
        chosen.push_back(usable[k * (usable.size() - 1) / (cap - 1)]);
      }
    }
    for (std::size_t i : chosen) {
      const MarkingMeasurement& meas = measurements[i];
      const auto slot = state->slot_of_frame.find(meas.frame_index);
      if (slot == state->slot_of_frame.end()) continue;
      std::array<Eigen::Vector2d, 4> corners_uv = meas.corners_uv;
      // Whole views are re-measured on the road plane; a partial view keeps its corners as
      // labeled (its rectangle on another plane could move a cut side onto a measured one).
      if (meas.Complete() && !meas.outline_uv.empty() && axis.norm() > 0.0) {
        const Eigen::Isometry3d T_map_cam = state->frames[slot->second].ToIsometry() * T_base_cam;
        std::array<Eigen::Vector2d, 4> on_plane;
        if (MeasureCornersOnPlane(camera, T_map_cam, plane, axis, corners, meas.outline_uv,
                                  &on_plane)) {
          corners_uv = on_plane;
        }
      }
      for (int c = 0; c < 4; ++c) {
        // A cut corner is no measurement (partial views): its sides may still be.
        if (!meas.CornerMeasured(c) || !corners_uv[c].allFinite()) continue;
        if (!ProjectsNearImage(camera, *state, slot->second, corners[c],
                               options.max_outside_image_px))
          continue;
        state->corner_measurements.push_back({m, c, slot->second, corners_uv[c]});
      }
      for (int side = 0; side < 4; ++side) {
        if (!meas.side_measured[side]) continue;
        if (meas.CornerMeasured(side) && meas.CornerMeasured((side + 1) % 4)) continue;
        for (const Eigen::Vector2d& uv : meas.side_uv[side]) {
          state->edge_measurements.push_back({m, side, slot->second, uv});
        }
      }
    }
  }
}

namespace {

// A lane pixel's ground point on the viewing frame's own ground (the plane its front end
// mapped the frame's pixels onto: FrameRecord::ground_base, base_link's z = 0 unless
// ipm.ground is trajectory), so that the segment it is given is where the front end put the
// lane's points. False when the ray does not descend to that plane ahead of the camera.
// (Re-intersecting it with the road surface the window's poses give there, RoadSurfaceNear,
// was measured and is not done: docs/backend.md, "The front end's ground".)
bool OntoFrameGround(const PinholeCamera& camera, const Eigen::Isometry3d& T_map_cam,
                     const Eigen::Isometry3d& T_map_base, const RoadPlane& ground_base,
                     const Eigen::Vector2d& uv, Eigen::Vector3d* p_map) {
  const Eigen::Vector2d xy = camera.UndistortToNormalized(uv);
  const Eigen::Vector3d ray_map = T_map_cam.linear() * Eigen::Vector3d(xy.x(), xy.y(), 1.0);
  const Eigen::Vector3d normal_map = T_map_base.linear() * ground_base.normal;
  const double descent = normal_map.dot(ray_map);
  if (!(descent < -Ipm::kMinRayDescent * ray_map.norm())) return false;
  const double lambda =
      normal_map.dot(T_map_base * ground_base.point - T_map_cam.translation()) / descent;
  if (!(lambda > 0.0)) return false;
  *p_map = T_map_cam.translation() + lambda * ray_map;
  return true;
}

// Re-intersections of a lane pixel's ray with the lane's own surface (OntoLaneSurface).
constexpr int kLaneSurfaceIterations = 3;

// A lane closer than this (sine of the angle) to the viewing frame's lateral axis gives no
// lane surface (LaneSurfaceNormal).
constexpr double kMinLaneSurfaceSine = 0.3;

// The plane through the lane's point `closest` that holds the lane's direction there and the
// viewing frame's lateral axis (its cross slope); the frame's own road plane when the lane
// runs across the frame's heading.
Eigen::Vector3d LaneSurfaceNormal(const CatmullRomSpline& spline,
                                  const CatmullRomSpline::ClosestPoint& closest,
                                  const Eigen::Isometry3d& T_map_base) {
  const Eigen::Vector3d normal = spline.Derivative(closest.s).cross(T_map_base.linear().col(1));
  const double norm = normal.norm();
  if (!(norm > kMinLaneSurfaceSine * spline.Derivative(closest.s).norm())) {
    return T_map_base.linear().col(2);
  }
  return normal.z() >= 0.0 ? Eigen::Vector3d(normal / norm) : Eigen::Vector3d(-normal / norm);
}

// Moves a lane pixel's ground point from the viewing frame's road plane onto the lane's own
// surface (LaneSurfaceNormal through its closest point) and finds the closest point again,
// kLaneSurfaceIterations times. Why: on a grade change, a crest or a wave the road ahead is
// not in the viewing frame's plane (0.3 m off at 20 m on a crest from +6 % to -4 %);
// flat-ground IPM then puts the pixel meters along and, scaled by its lateral offset,
// sideways from its line, so it was matched to the wrong segment (its PPSR measured the
// distance to a wrong chord of the projected line) or dropped by the distance gate, the far
// line on one side more than the others: a bias of the camera's roll on hills. The lane's
// height is the map's own estimate (under the road-surface prior). False when the ray does
// not meet that surface ahead of the camera.
bool OntoLaneSurface(const PinholeCamera& camera, const Eigen::Isometry3d& T_map_cam,
                     const Eigen::Isometry3d& T_map_base, const Eigen::Vector2d& uv,
                     const CatmullRomSpline& spline, Eigen::Vector3d* p_map,
                     CatmullRomSpline::ClosestPoint* closest) {
  const Eigen::Vector2d xy = camera.UndistortToNormalized(uv);
  const Eigen::Vector3d ray_map = T_map_cam.linear() * Eigen::Vector3d(xy.x(), xy.y(), 1.0);
  for (int iteration = 0; iteration < kLaneSurfaceIterations; ++iteration) {
    const Eigen::Vector3d normal_map = LaneSurfaceNormal(spline, *closest, T_map_base);
    const double descent = normal_map.dot(ray_map);
    if (descent >= 0.0) return false;
    const double lambda = normal_map.dot(closest->point - T_map_cam.translation()) / descent;
    if (lambda <= 0.0) return false;
    *p_map = T_map_cam.translation() + lambda * ray_map;
    *closest = spline.FindClosest(*p_map);
  }
  return true;
}

}  // namespace

void CollectLanePixels(const WindowSnapshot& snapshot, const BackendOptions& options,
                       WindowState* state) {
  const PinholeCamera camera(snapshot.camera);
  for (std::size_t l = 0; l < snapshot.lanes.size(); ++l) {
    const WindowLane& lane = snapshot.lanes[l];
    if (lane.control_points_map.size() < 4) continue;
    const CatmullRomSpline spline(lane.control_points_map);
    for (const LaneMeasurement& m : lane.measurements) {
      const auto slot = state->slot_of_frame.find(m.frame_index);
      if (slot == state->slot_of_frame.end()) continue;
      std::vector<std::size_t> selected;
      for (std::size_t i = 0; i < m.points.size(); ++i) {
        if (m.selected[i]) selected.push_back(i);
      }
      const std::size_t cap = static_cast<std::size_t>(options.max_lane_points_per_observation);
      const double step = selected.size() > cap ? static_cast<double>(selected.size()) / cap : 1.0;
      const Eigen::Isometry3d T_map_base = state->frames[slot->second].ToIsometry();
      const Eigen::Isometry3d T_map_cam = T_map_base * snapshot.T_base_cam;
      const RoadPlane& ground_base = snapshot.frames[slot->second].ground_base;
      for (double k = 0.0; k < static_cast<double>(selected.size()); k += step) {
        const LanePoint& point = m.points[selected[static_cast<std::size_t>(k)]];
        Eigen::Vector3d p_map;
        if (!OntoFrameGround(camera, T_map_cam, T_map_base, ground_base, point.uv, &p_map))
          continue;
        CatmullRomSpline::ClosestPoint closest = spline.FindClosest(p_map);
        if (closest.distance_m > options.max_lane_pixel_distance_m) continue;
        if (options.lane_pixels_on_lane_surface &&
            !OntoLaneSurface(camera, T_map_cam, T_map_base, point.uv, spline, &p_map, &closest)) {
          continue;
        }
        if (closest.s <= 0.0 || closest.s >= spline.NumSegments()) continue;  // past an end
        const auto& cps = lane.control_points_map;
        if (!ProjectsNearImage(camera, *state, slot->second, cps[closest.segment + 1],
                               options.max_outside_image_px) ||
            !ProjectsNearImage(camera, *state, slot->second, cps[closest.segment + 2],
                               options.max_outside_image_px)) {
          continue;
        }
        state->lane_pixels.push_back({l, slot->second, point.uv, closest.segment, closest.u, p_map,
                                      T_map_base.inverse() * p_map});
      }
    }
  }
}

void RefreshPsrPoints(const WindowSnapshot& snapshot, const BackendOptions& options,
                      WindowState* state) {
  const PinholeCamera camera(snapshot.camera);
  const Eigen::Isometry3d T_base_cam = state->extrinsic.ToIsometry();
  std::vector<std::optional<CatmullRomSpline>> splines(snapshot.lanes.size());
  for (LanePixel& px : state->lane_pixels) {
    const auto& cps = state->control_points[px.lane];
    if (cps.size() < 4) continue;
    if (!splines[px.lane]) splines[px.lane].emplace(cps);
    const CatmullRomSpline& spline = *splines[px.lane];
    const Eigen::Isometry3d T_map_base = state->frames[px.slot].ToIsometry();
    const Eigen::Isometry3d T_map_cam = T_map_base * T_base_cam;
    Eigen::Vector3d p_map;
    if (!OntoFrameGround(camera, T_map_cam, T_map_base, snapshot.frames[px.slot].ground_base, px.uv,
                         &p_map)) {
      continue;
    }
    CatmullRomSpline::ClosestPoint closest = spline.FindClosest(p_map);
    if (options.lane_pixels_on_lane_surface &&
        !OntoLaneSurface(camera, T_map_cam, T_map_base, px.uv, spline, &p_map, &closest)) {
      continue;
    }
    // Past an end the old assignment stands (the segments are those the pixel was given).
    if (closest.s <= 0.0 || closest.s >= spline.NumSegments()) continue;
    px.segment = closest.segment;
    px.u = closest.u;
    px.q_map = p_map;
    px.p_base = T_map_base.inverse() * p_map;
  }
}

}  // namespace window_solve
}  // namespace ipm_road_mapper
