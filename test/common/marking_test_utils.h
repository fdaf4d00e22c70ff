// Helpers the marking tests share (test_marking_extent, test_partial_view_association).
#pragma once

#include <Eigen/Core>
#include <array>

namespace ipm_road_mapper {

// Rectangle [x0, x1] x [y0, y1] on the ground (z = 0), counter-clockwise from (x0, y0).
inline std::array<Eigen::Vector3d, 4> Rect(double x0, double x1, double y0, double y1) {
  return {Eigen::Vector3d(x0, y0, 0), Eigen::Vector3d(x1, y0, 0), Eigen::Vector3d(x1, y1, 0),
          Eigen::Vector3d(x0, y1, 0)};
}

}  // namespace ipm_road_mapper
