// The static 3D world of a synthetic drive: the road, its lane lines (painted pieces on the
// surface plus the true center polyline) and its markings (shape polygons on the surface
// plus the true bounding rectangle). Built once from the scenario.
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>
#include <utility>
#include <vector>

#include "ipm_road_mapper/core/frontend/class_table.h"
#include "ipm_road_mapper/sim/road.h"
#include "ipm_road_mapper/sim/scenario.h"

namespace ipm_road_mapper {
namespace sim {

// Paint color of an element (the gray image draws them differently).
enum class PaintColor { kWhite, kYellow };

// A vertex on the road: its map point and road coordinates (s, l).
struct SurfaceVertex {
  Eigen::Vector3d p_map = Eigen::Vector3d::Zero();
  double s = 0.0;
  double l = 0.0;
};

// A convex polygon lying on the road surface (edges densified so that it follows the
// surface), with the s range it covers (for culling).
struct SurfacePolygon {
  std::vector<SurfaceVertex> vertices;
  double s_min = 0.0;
  double s_max = 0.0;
};

// A lane line: painted pieces (<= piece_length_m quads, one instance per frame together)
// and the painted s intervals.
struct SimLaneLine {
  int id = 0;  // 1-based, right to left
  int class_id = 0;
  std::string class_name;
  LaneStyle style = LaneStyle::kSolid;
  PaintColor color = PaintColor::kWhite;
  double offset_m = 0.0;                           // lateral offset of the line's center
  std::vector<SurfacePolygon> pieces;              // sorted by s
  std::vector<std::pair<double, double>> painted;  // painted [s0, s1], sorted
  // True when s lies on paint, at least `margin_m` from the ends of a painted interval.
  bool IsPainted(double s, double margin_m = 0.0) const;
};

// A ground marking: its shape (convex components) and its true bounding rectangle, both
// defined in the marking's local frame (u along its heading, w to its left, meters, origin
// at the nominal center) and lifted onto the surface.
struct SimMarking {
  int id = 0;  // 1-based
  int class_id = 0;
  std::string class_name;
  PaintColor color = PaintColor::kWhite;
  Eigen::Vector2d origin_xy = Eigen::Vector2d::Zero();  // local frame in the map (horizontal)
  Eigen::Vector2d axis_u = Eigen::Vector2d::UnitX();
  Eigen::Vector2d axis_w = Eigen::Vector2d::UnitY();
  double s_origin = 0.0;
  std::vector<std::vector<Eigen::Vector2d>> shape_uw;    // convex components, local meters
  std::array<Eigen::Vector2d, 4> rect_uw;                // bounding rectangle, CCW from above
  std::array<Eigen::Vector3d, 4> corners_map;            // rect_uw on the surface
  Eigen::Vector3d center_map = Eigen::Vector3d::Zero();  // mean of the corners
  std::vector<SurfacePolygon> components;                // shape_uw on the surface
  double s_min = 0.0, s_max = 0.0;
  double l_min = 0.0, l_max = 0.0;  // lateral extent of the painted shape
  int placement = 0;                // index in ScenarioOptions::markings
};

// Convex shape components of a marking class in normalized coordinates: a in [0, 1] along
// the heading (0 = rear), b in [0, 1] across (0 = right side). The union of the components
// touches all four sides of the unit square. `text` is used by speed_limit.
std::vector<std::vector<Eigen::Vector2d>> MarkingShape(const std::string& class_name,
                                                       const std::string& text);

// The static world.
class SimWorld {
 public:
  // Places lane lines over s in [line_start_s, line_end_s] and the scenario's markings.
  // Throws OptionsError when two markings overlap (their masks would fight).
  SimWorld(const ScenarioOptions& scenario, const ClassTable& classes, double line_start_s,
           double line_end_s);

  const RoadModel& road() const { return road_; }
  const std::vector<SimLaneLine>& lane_lines() const { return lane_lines_; }
  const std::vector<SimMarking>& markings() const { return markings_; }

  // A marking-local point (u, w) lifted onto the surface.
  SurfaceVertex MarkingPoint(const SimMarking& marking, const Eigen::Vector2d& uw) const;

  // The true center polyline of a lane line over [s0, s1], a point every `step_m` of s.
  std::vector<Eigen::Vector3d> LanePoints(const SimLaneLine& line, double s0, double s1,
                                          double step_m = 0.1) const;

 private:
  void PlaceMarkings(const ScenarioOptions& scenario);
  void AddMarking(const MarkingPlacement& placement, int placement_index, double s, double l);
  void CheckOverlaps() const;
  void BuildLaneLines(const ScenarioOptions& scenario, const ClassTable& classes,
                      double line_start_s, double line_end_s);
  SurfacePolygon LiftMarkingPolygon(const SimMarking& marking,
                                    const std::vector<Eigen::Vector2d>& polygon_uw) const;

  RoadModel road_;
  std::vector<SimLaneLine> lane_lines_;
  std::vector<SimMarking> markings_;
};

}  // namespace sim
}  // namespace ipm_road_mapper
