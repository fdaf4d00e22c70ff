#include "ipm_road_mapper/core/mapper/lane_topology.h"

#include <algorithm>
#include <memory>

#include "ipm_road_mapper/core/geometry/catmull_rom_spline.h"

namespace ipm_road_mapper {
namespace {

// A start (or end) this close along to the other lane's end continues it end to start.
constexpr double kEndToEndM = 2.0;
// How far along the linked lane it must have left the other (else they run side by side).
constexpr double kLeaveAfterM = 10.0;
// Its direction there within this of the other's (cos 30 deg).
constexpr double kMinDirectionCos = 0.87;

// Horizontal distance of a point from a lane's curve, the curve's point and unit tangent.
struct Nearest {
  double distance_m = 1e18;
  Eigen::Vector3d tangent = Eigen::Vector3d::Zero();
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
};

// The closest point of the lane's part near p.
Nearest NearestOn(const MapLane& lane, const Eigen::Vector3d& p) {
  Nearest out;
  std::size_t first = 0, last = 0;
  if (!ControlPointRangeNear(lane.control_points_map, {p}, 8.0, &first, &last)) return out;
  const CatmullRomSpline spline(std::vector<Eigen::Vector3d>(
      lane.control_points_map.begin() + first, lane.control_points_map.begin() + last + 1));
  const CatmullRomSpline::ClosestPoint closest = spline.FindClosest(p);
  out.distance_m = (closest.point - p).head<2>().norm();
  out.point = closest.point;
  const Eigen::Vector3d d = spline.Derivative(closest.s);
  if (d.norm() > 1e-9) out.tangent = d.normalized();
  return out;
}

// Whether `lane`'s start (from_start) or end lies on `other` and `lane` leaves it there.
bool Touches(const MapLane& lane, const MapLane& other, bool from_start, double radius_m) {
  const std::vector<Eigen::Vector3d>& cps = lane.control_points_map;
  const CatmullRomSpline spline(cps);
  const double length = spline.Length();
  if (length < 1e-6) return false;
  const std::vector<Eigen::Vector3d> samples = spline.SampleByArcLength(1.0);
  const Eigen::Vector3d& tip = from_start ? samples.front() : samples.back();
  const Nearest at_tip = NearestOn(other, tip);
  if (at_tip.distance_m > radius_m) return false;
  const std::size_t k = from_start ? std::min<std::size_t>(1, samples.size() - 1)
                                   : (samples.size() >= 2 ? samples.size() - 2 : 0);
  Eigen::Vector3d direction = from_start ? samples[k] - tip : tip - samples[k];
  if (direction.norm() < 1e-9 || at_tip.tangent.isZero()) return false;
  direction.normalize();
  if (direction.head<2>().dot(at_tip.tangent.head<2>()) < kMinDirectionCos) return false;
  const std::vector<Eigen::Vector3d>& ocps = other.control_points_map;
  const Eigen::Vector3d other_tip = from_start ? ocps[ocps.size() - 2] : ocps[1];
  if ((tip - other_tip).head<2>().norm() <= kEndToEndM) return true;  // end to start
  // Leaves it: kLeaveAfterM along, no longer on it.
  const std::size_t steps = static_cast<std::size_t>(kLeaveAfterM);
  if (samples.size() <= steps) return false;
  const Eigen::Vector3d& probe = from_start ? samples[steps] : samples[samples.size() - 1 - steps];
  return NearestOn(other, probe).distance_m > radius_m;
}

void AddOnce(std::vector<std::uint64_t>* ids, std::uint64_t id) {
  if (std::find(ids->begin(), ids->end(), id) == ids->end()) ids->push_back(id);
}

}  // namespace

void LinkLaneTopology(std::vector<MapLane>* lanes, double radius_m) {
  for (MapLane& lane : *lanes) {
    lane.predecessors.clear();
    lane.successors.clear();
  }
  for (std::size_t a = 0; a < lanes->size(); ++a) {
    for (std::size_t b = 0; b < lanes->size(); ++b) {
      MapLane& x = (*lanes)[a];
      MapLane& y = (*lanes)[b];
      if (a == b || x.control_points_map.size() < 4 || y.control_points_map.size() < 4) continue;
      if (Touches(x, y, /*from_start=*/true, radius_m)) {  // x continues from y
        AddOnce(&x.predecessors, y.id);
        AddOnce(&y.successors, x.id);
      }
      if (Touches(x, y, /*from_start=*/false, radius_m)) {  // x leads into y
        AddOnce(&x.successors, y.id);
        AddOnce(&y.predecessors, x.id);
      }
    }
  }
}

}  // namespace ipm_road_mapper
