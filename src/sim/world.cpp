#include "ipm_road_mapper/sim/world.h"

#include <algorithm>
#include <cmath>

namespace ipm_road_mapper {
namespace sim {
namespace {

constexpr double kMaxMarkingEdgeM = 0.25;  // marking edges are densified to follow the surface
constexpr double kLineCutMarginM = 0.5;    // lane lines stop this far before a crossing marking

using Interval = std::pair<double, double>;

// Removes `cut` from every interval of `intervals`.
std::vector<Interval> Subtract(const std::vector<Interval>& intervals, const Interval& cut) {
  std::vector<Interval> out;
  for (const Interval& iv : intervals) {
    if (cut.second <= iv.first || cut.first >= iv.second) {
      out.push_back(iv);
      continue;
    }
    if (cut.first > iv.first) out.emplace_back(iv.first, cut.first);
    if (cut.second < iv.second) out.emplace_back(cut.second, iv.second);
  }
  return out;
}

PaintColor ColorOf(const std::string& class_name) {
  return class_name.find("yellow") != std::string::npos ? PaintColor::kYellow : PaintColor::kWhite;
}

}  // namespace

bool SimLaneLine::IsPainted(double s, double margin_m) const {
  for (const auto& [s0, s1] : painted) {
    if (s >= s0 + margin_m && s <= s1 - margin_m) return true;
    if (s0 > s) break;
  }
  return false;
}

SimWorld::SimWorld(const ScenarioOptions& scenario, const ClassTable& classes, double line_start_s,
                   double line_end_s)
    : road_(scenario.road) {
  PlaceMarkings(scenario);
  CheckOverlaps();
  BuildLaneLines(scenario, classes, line_start_s, line_end_s);
}

SurfaceVertex SimWorld::MarkingPoint(const SimMarking& marking, const Eigen::Vector2d& uw) const {
  SurfaceVertex v;
  const Eigen::Vector2d xy = marking.origin_xy + uw.x() * marking.axis_u + uw.y() * marking.axis_w;
  const double s_hint =
      marking.s_origin + (xy - marking.origin_xy).dot(road_.Centerline(marking.s_origin).Tangent());
  const Eigen::Vector2d sl = road_.Locate(xy, s_hint);
  v.s = sl.x();
  v.l = sl.y();
  v.p_map = Eigen::Vector3d(xy.x(), xy.y(), road_.Height(v.s, v.l));
  return v;
}

SurfacePolygon SimWorld::LiftMarkingPolygon(const SimMarking& marking,
                                            const std::vector<Eigen::Vector2d>& polygon_uw) const {
  SurfacePolygon polygon;
  polygon.s_min = 1e300;
  polygon.s_max = -1e300;
  for (std::size_t i = 0; i < polygon_uw.size(); ++i) {
    const Eigen::Vector2d& a = polygon_uw[i];
    const Eigen::Vector2d& b = polygon_uw[(i + 1) % polygon_uw.size()];
    const int n = std::max(1, static_cast<int>(std::ceil((b - a).norm() / kMaxMarkingEdgeM)));
    for (int k = 0; k < n; ++k) {
      const SurfaceVertex v = MarkingPoint(marking, a + (b - a) * (static_cast<double>(k) / n));
      polygon.s_min = std::min(polygon.s_min, v.s);
      polygon.s_max = std::max(polygon.s_max, v.s);
      polygon.vertices.push_back(v);
    }
  }
  return polygon;
}

void SimWorld::AddMarking(const MarkingPlacement& placement, int placement_index, double s,
                          double l) {
  SimMarking m;
  m.placement = placement_index;
  m.id = static_cast<int>(markings_.size()) + 1;
  m.class_id = placement.class_id;
  m.class_name = placement.class_name;
  m.color = ColorOf(placement.class_name);
  const CenterlinePoint c = road_.Centerline(s);
  const double heading = c.heading + placement.heading_deg * M_PI / 180.0;
  m.origin_xy = c.xy + l * c.Normal();
  m.axis_u = Eigen::Vector2d(std::cos(heading), std::sin(heading));
  m.axis_w = Eigen::Vector2d(-std::sin(heading), std::cos(heading));
  m.s_origin = s;
  Eigen::Vector2d lo(1e300, 1e300), hi(-1e300, -1e300);
  for (const auto& component : MarkingShape(placement.class_name, placement.text)) {
    std::vector<Eigen::Vector2d> polygon;
    for (const Eigen::Vector2d& ab : component) {
      polygon.emplace_back((ab.x() - 0.5) * placement.length_m, (ab.y() - 0.5) * placement.width_m);
      lo = lo.cwiseMin(polygon.back());
      hi = hi.cwiseMax(polygon.back());
    }
    m.shape_uw.push_back(polygon);
  }
  // The true rectangle is the painted extent, counter-clockwise seen from above starting at
  // the rear right corner.
  m.rect_uw = {{{lo.x(), lo.y()}, {hi.x(), lo.y()}, {hi.x(), hi.y()}, {lo.x(), hi.y()}}};
  m.s_min = 1e300;
  m.s_max = -1e300;
  for (int i = 0; i < 4; ++i) {
    const SurfaceVertex v = MarkingPoint(m, m.rect_uw[i]);
    m.corners_map[i] = v.p_map;
    m.center_map += 0.25 * v.p_map;
    m.s_min = std::min(m.s_min, v.s);
    m.s_max = std::max(m.s_max, v.s);
  }
  m.l_min = 1e300;
  m.l_max = -1e300;
  for (const auto& polygon : m.shape_uw) {
    m.components.push_back(LiftMarkingPolygon(m, polygon));
    for (const SurfaceVertex& v : m.components.back().vertices) {
      m.l_min = std::min(m.l_min, v.l);
      m.l_max = std::max(m.l_max, v.l);
    }
  }
  markings_.push_back(std::move(m));
}

void SimWorld::CheckOverlaps() const {
  // Conservative: the (s, l) boxes of the painted shapes must not intersect.
  for (std::size_t i = 0; i < markings_.size(); ++i) {
    for (std::size_t j = i + 1; j < markings_.size(); ++j) {
      const SimMarking& a = markings_[i];
      const SimMarking& b = markings_[j];
      if (a.s_min < b.s_max && b.s_min < a.s_max && a.l_min < b.l_max && b.l_min < a.l_max) {
        throw OptionsError("markings[" + std::to_string(a.placement) + "] and markings[" +
                           std::to_string(b.placement) + "]: markings overlap near s = " +
                           std::to_string(static_cast<int>(a.s_origin)) + " m");
      }
    }
  }
}

void SimWorld::PlaceMarkings(const ScenarioOptions& scenario) {
  for (std::size_t index = 0; index < scenario.markings.size(); ++index) {
    const MarkingPlacement& placement = scenario.markings[index];
    std::vector<double> laterals;
    if (placement.has_offset) {
      laterals.push_back(placement.offset_m);
    } else {
      for (int lane : placement.lanes) laterals.push_back(road_.LaneCenterOffset(lane));
    }
    for (double l0 : laterals) {
      for (int i = 0; i < placement.count_along; ++i) {
        for (int j = 0; j < placement.count_across; ++j) {
          const double l = l0 + (j - 0.5 * (placement.count_across - 1)) * placement.step_across_m;
          AddMarking(placement, static_cast<int>(index), placement.s_m + i * placement.step_along_m,
                     l);
        }
      }
    }
  }
}

void SimWorld::BuildLaneLines(const ScenarioOptions& scenario, const ClassTable& classes,
                              double line_start_s, double line_end_s) {
  const RoadOptions& ro = scenario.road;
  const double half_width = 0.5 * ro.line_width_m;
  for (int i = 0; i <= ro.lanes; ++i) {
    SimLaneLine line;
    line.id = i + 1;
    line.class_id = ro.line_class_ids[i];
    line.class_name = ro.line_classes[i];
    const ClassInfo* info = classes.Find(line.class_id);
    line.style = info && info->style == LaneStyle::kDashed ? LaneStyle::kDashed : LaneStyle::kSolid;
    line.color = ColorOf(line.class_name);
    line.offset_m = road_.LineOffset(i);
    std::vector<Interval> painted;
    if (line.style == LaneStyle::kDashed) {
      const double period = ro.dash_length_m + ro.gap_length_m;
      for (double s = std::floor(line_start_s / period) * period; s < line_end_s; s += period) {
        const double a = std::max(s, line_start_s), b = std::min(s + ro.dash_length_m, line_end_s);
        if (b > a) painted.emplace_back(a, b);
      }
    } else {
      painted.emplace_back(line_start_s, line_end_s);
    }
    // Lines stop at markings that cross them (crosswalks, stop lines).
    for (const SimMarking& m : markings_) {
      if (line.offset_m + half_width + 0.2 > m.l_min &&
          line.offset_m - half_width - 0.2 < m.l_max) {
        painted = Subtract(painted, {m.s_min - kLineCutMarginM, m.s_max + kLineCutMarginM});
      }
    }
    line.painted = painted;
    for (const auto& [a, b] : painted) {
      const int n = std::max(1, static_cast<int>(std::ceil((b - a) / ro.piece_length_m)));
      for (int k = 0; k < n; ++k) {
        const double s0 = a + (b - a) * k / n, s1 = a + (b - a) * (k + 1) / n;
        SurfacePolygon piece;
        piece.s_min = s0;
        piece.s_max = s1;
        for (const auto& [s, dl] : {std::pair<double, double>{s0, -half_width},
                                    {s1, -half_width},
                                    {s1, half_width},
                                    {s0, half_width}}) {
          const double l = line.offset_m + dl;
          piece.vertices.push_back({road_.SurfacePoint(s, l), s, l});
        }
        line.pieces.push_back(std::move(piece));
      }
    }
    lane_lines_.push_back(std::move(line));
  }
}

std::vector<Eigen::Vector3d> SimWorld::LanePoints(const SimLaneLine& line, double s0, double s1,
                                                  double step_m) const {
  std::vector<Eigen::Vector3d> points;
  const int n = static_cast<int>(std::floor((s1 - s0) / step_m + 1e-9));
  for (int k = 0; k <= n; ++k) points.push_back(road_.SurfacePoint(s0 + k * step_m, line.offset_m));
  return points;
}

}  // namespace sim
}  // namespace ipm_road_mapper
