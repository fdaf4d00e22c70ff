// Lane fragments with histories, built directly (no masks): lines as functions of arc
// length and lanes observed along them, for the join and tracker tests.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <functional>
#include <random>

#include "ipm_road_mapper/core/map/road_map.h"

namespace ipm_road_mapper {
namespace test {

// A line as a function of arc length s: its point in the map frame.
using Line = std::function<Eigen::Vector3d(double s)>;

inline Line Straight(double y) {
  return [y](double s) { return Eigen::Vector3d(s, y, 0.0); };
}

// A left turn of radius R from the origin heading +x, `offset` to the left of it.
inline Line Arc(double R, double offset) {
  return [R, offset](double s) {
    const double a = s / R, r = R - offset;
    return Eigen::Vector3d(r * std::sin(a), R - r * std::cos(a), 0.0);
  };
}

// A lane along `line` over [s0, s1] (control points every 3 m, phantoms included), observed
// in frames [f0, f1): each frame sees 12 points on the 3 m of line just behind a point that
// moves from s0 to s1, with a per-frame offset (pose noise, 0.1 m) and per-point noise.
inline LaneElement MakeLane(std::uint64_t id, int class_id, const Line& line, double s0, double s1,
                            std::size_t f0, std::size_t f1, std::mt19937* rng) {
  LaneElement lane;
  lane.id = id;
  lane.class_id = class_id;
  for (double s = s0 - 3.0; s <= s1 + 3.0 + 1e-9; s += 3.0) {
    lane.control_points_map.push_back(line(s));
  }
  std::normal_distribution<double> frame_noise(0.0, 0.1), point_noise(0.0, 0.03);
  for (std::size_t f = f0; f < f1; ++f) {
    LaneMeasurement m;
    m.frame_index = f;
    const double s_end = s0 + 3.0 + (s1 - s0 - 3.0) * (f - f0) / std::max<double>(1, f1 - f0 - 1);
    const Eigen::Vector3d shift(0.0, frame_noise(*rng), 0.0);
    for (int k = 0; k < 12; ++k) {
      m.selected_map.push_back(line(s_end - 3.0 + 0.25 * k) + shift +
                               Eigen::Vector3d(0.0, point_noise(*rng), 0.0));
    }
    lane.history.push_back(std::move(m));
  }
  lane.first_frame = f0;
  lane.last_frame = f1 - 1;
  return lane;
}

}  // namespace test
}  // namespace ipm_road_mapper
