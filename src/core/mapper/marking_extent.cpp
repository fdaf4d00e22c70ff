#include "ipm_road_mapper/core/mapper/marking_extent.h"

namespace ipm_road_mapper {
namespace {

// Unit direction (x-y) of side i, from corner i to corner i + 1; zero when degenerate.
Eigen::Vector2d SideDirection(const std::array<Eigen::Vector3d, 4>& corners, int i) {
  const Eigen::Vector2d d = (corners[(i + 1) % 4] - corners[i]).head<2>();
  return d.norm() > 1e-9 ? Eigen::Vector2d(d.normalized()) : Eigen::Vector2d::Zero();
}

}  // namespace

int SideAlignedShift(const std::array<Eigen::Vector3d, 4>& element_corners_map,
                     const std::array<Eigen::Vector3d, 4>& observation_corners_map) {
  int best_shift = 0;
  double best = -1e18;
  for (int shift = 0; shift < 4; ++shift) {
    double agreement = 0.0;
    for (int i = 0; i < 4; ++i) {
      agreement += SideDirection(element_corners_map, i)
                       .dot(SideDirection(observation_corners_map, (i + shift) % 4));
    }
    if (agreement > best) {
      best = agreement;
      best_shift = shift;
    }
  }
  return best_shift;
}

void UpdateExtent(const std::array<Eigen::Vector3d, 4>& observation_corners_map,
                  const std::array<bool, 4>& observation_sides, bool owned,
                  MarkingElement* element) {
  std::array<Eigen::Vector3d, 4>& corners = element->corners_map;
  // All sides' moves from the corners before this update.
  std::array<double, 4> move{{0.0, 0.0, 0.0, 0.0}};
  std::array<Eigen::Vector2d, 4> outward;
  for (int s = 0; s < 4; ++s) {
    const Eigen::Vector2d along = SideDirection(corners, s);
    outward[s] = Eigen::Vector2d(along.y(), -along.x());  // corners are counter-clockwise
    const int e = (s + 1) % 4;
    const double element_offset = 0.5 * outward[s].dot(corners[s].head<2>() + corners[e].head<2>());
    const double observed_offset = 0.5 * outward[s].dot(observation_corners_map[s].head<2>() +
                                                        observation_corners_map[e].head<2>());
    const double delta = observed_offset - element_offset;
    if (observation_sides[s]) {
      if (!element->side_measured[s]) {
        move[s] = delta;  // the first measurement replaces the lower bound
        element->side_measured[s] = true;
        element->side_views[s] = 1;
      } else {
        ++element->side_views[s];
        if (!owned) move[s] = delta / static_cast<double>(element->side_views[s]);
      }
    } else if (!element->side_measured[s] && delta > 0.0) {
      move[s] = delta;  // the view reaches farther than any before: the extent grows
    }
  }
  for (int s = 0; s < 4; ++s) {
    if (move[s] == 0.0) continue;
    const Eigen::Vector3d shift(move[s] * outward[s].x(), move[s] * outward[s].y(), 0.0);
    corners[s] += shift;
    corners[(s + 1) % 4] += shift;
  }
}

std::array<Eigen::Vector3d, 4> RectifyPartialExtent(
    const std::array<Eigen::Vector3d, 4>& before_map,
    const std::array<Eigen::Vector3d, 4>& refined_map, const std::array<bool, 4>& side_measured) {
  const bool any_measured =
      side_measured[0] || side_measured[1] || side_measured[2] || side_measured[3];
  // Side s of a counter-clockwise rectangle runs along side 0's direction turned by s x 90 deg:
  // each side turned back by s x 90 deg votes for side 0's direction.
  Eigen::Vector2d u = Eigen::Vector2d::Zero();
  for (int s = 0; s < 4; ++s) {
    if (any_measured && !side_measured[s]) continue;
    Eigen::Vector2d d = (refined_map[(s + 1) % 4] - refined_map[s]).head<2>();
    for (int k = 0; k < s; ++k) d = Eigen::Vector2d(d.y(), -d.x());  // turn by -90 deg
    u += d;
  }
  if (!(u.norm() > 1e-9)) return refined_map;
  u.normalize();
  const Eigen::Vector2d v(-u.y(), u.x());
  // Outward normals of the sides (as in UpdateExtent: (along.y, -along.x)).
  const std::array<Eigen::Vector2d, 4> outward{{-v, u, v, -u}};
  std::array<double, 4> offset;
  for (int s = 0; s < 4; ++s) {
    const std::array<Eigen::Vector3d, 4>& source = side_measured[s] ? refined_map : before_map;
    offset[s] = 0.5 * outward[s].dot(source[s].head<2>() + source[(s + 1) % 4].head<2>());
  }
  std::array<Eigen::Vector3d, 4> corners;
  for (int c = 0; c < 4; ++c) {
    const int previous = (c + 3) % 4;  // corner c lies on sides c - 1 and c
    const Eigen::Vector2d xy = offset[c] * outward[c] + offset[previous] * outward[previous];
    corners[c] = Eigen::Vector3d(xy.x(), xy.y(), refined_map[c].z());
  }
  return corners;
}

}  // namespace ipm_road_mapper
