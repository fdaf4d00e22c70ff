#include "ipm_road_mapper/core/geometry/lane_end_fit.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "ipm_road_mapper/core/geometry/catmull_rom_spline.h"

namespace ipm_road_mapper {
namespace {

// Huber re-weighting rounds of the least-squares step.
constexpr int kReweightRounds = 3;
// A point whose closest curve point is an end counts for refinement only this close to it
// (farther, it lies beyond the end: extension material, not a sample of the curve).
constexpr double kEndSnapM = 0.05;
// The slice FitLaneEndsNear hands to FitLaneEnds: the control points within this of the
// points (an end beyond an association gap included) and this many more on each side, so
// that the slice's own ends (phantoms to FitLaneEnds) are never moved or grown.
constexpr double kSliceReachM = 50.0;
constexpr std::size_t kSliceMarginPoints = 4;

// Catmull-Rom basis weights of c_i..c_(i+3) at u (see catmull_rom_spline.h).
Eigen::Vector4d Basis(double u) {
  const double u2 = u * u, u3 = u2 * u;
  return 0.5 * Eigen::Vector4d(-u + 2.0 * u2 - u3, 2.0 - 5.0 * u2 + 3.0 * u3,
                               u + 4.0 * u2 - 3.0 * u3, -u2 + u3);
}

// Below this |curvature| (1/m) an end grows straight (the exact straight-line code).
constexpr double kMinArcCurvature = 1e-6;
// Points beyond a curved end count up to this turn of the arc (rad).
constexpr double kMaxArcTurn = 1.5;

// Appends control points at the end of `cps` (phantom last) for the points beyond it, along
// the arc of signed curvature `curvature` (0: straight). Returns how many were added.
int ExtendEnd(const LaneEndFitOptions& options, const std::vector<Eigen::Vector3d>& points,
              double curvature, std::vector<Eigen::Vector3d>* cps) {
  const std::size_t n = cps->size();
  const Eigen::Vector3d end = (*cps)[n - 2];
  Eigen::Vector3d tangent = end - (*cps)[n - 3];
  if (tangent.norm() < 1e-9) return 0;
  const double chord_m = tangent.head<2>().norm();
  tangent.normalize();
  const double horizontal = tangent.head<2>().norm();
  std::vector<double> beyond;
  if (std::abs(curvature) < kMinArcCurvature || horizontal < 1e-6) {
    for (const Eigen::Vector3d& p : points) {
      const Eigen::Vector3d d = p - end;
      const double along = d.dot(tangent);
      if (along <= 0.0) continue;
      if ((d - along * tangent).norm() > options.max_point_distance_m) continue;
      beyond.push_back(along);
    }
    if (static_cast<int>(beyond.size()) < options.min_points_to_extend) return 0;
    std::nth_element(beyond.begin(), beyond.end() - 2, beyond.end());
    const double reach = beyond[beyond.size() - 2];
    const int add = static_cast<int>(std::floor(reach / options.chord_spacing_m + 0.5));
    if (add <= 0) return 0;
    cps->pop_back();  // the old phantom
    for (int k = 1; k <= add; ++k) cps->push_back(end + k * options.chord_spacing_m * tangent);
    cps->push_back(2.0 * cps->back() - (*cps)[cps->size() - 2]);
    return add;
  }
  // The arc: the end's tangent is the last chord turned by half its angle; horizontal frame
  // (t along, l left) at the end, the arc's center at l = 1 / curvature.
  const double turn = 0.5 * curvature * chord_m;
  const Eigen::Vector2d chord_dir = tangent.head<2>() / horizontal;
  const Eigen::Vector2d t(std::cos(turn) * chord_dir.x() - std::sin(turn) * chord_dir.y(),
                          std::sin(turn) * chord_dir.x() + std::cos(turn) * chord_dir.y());
  const Eigen::Vector2d l(-t.y(), t.x());
  const double radius = 1.0 / std::abs(curvature), side = curvature > 0.0 ? 1.0 : -1.0;
  const double slope = tangent.z() / horizontal;  // dz per horizontal meter
  // Each point beyond the end measured across the arc and across the straight tangent line:
  // the points choose (median distance) whether the line goes on along the arc or straight
  // (leaving a curve, the path's curvature still has the arc's while the end is past it).
  std::vector<double> across_arc, across_line;
  for (const Eigen::Vector3d& p : points) {
    const Eigen::Vector2d d = (p - end).head<2>();
    // From the center: (radius sin(theta), -side radius cos(theta)) at arc angle theta.
    const Eigen::Vector2d v(d.dot(t), d.dot(l) - side * radius);
    const double theta = std::atan2(v.x(), -side * v.y());
    if (theta <= 0.0 || theta > kMaxArcTurn) continue;
    const double along = theta * radius;
    const double up = p.z() - end.z() - slope * along;
    const double across = std::hypot(v.norm() - radius, up);
    const Eigen::Vector3d e = p - end;
    const double straight_along = e.dot(tangent);
    const double straight_across =
        straight_along > 0.0 ? (e - straight_along * tangent).norm() : across;
    if (std::min(across, straight_across) > options.max_point_distance_m) continue;
    across_arc.push_back(across);
    across_line.push_back(straight_across);
    if (across > options.max_point_distance_m) continue;
    beyond.push_back(along);
  }
  if (!across_arc.empty()) {
    const std::size_t mid = across_arc.size() / 2;
    std::nth_element(across_arc.begin(), across_arc.begin() + mid, across_arc.end());
    std::nth_element(across_line.begin(), across_line.begin() + mid, across_line.end());
    if (across_line[mid] < across_arc[mid]) return ExtendEnd(options, points, 0.0, cps);
  }
  if (static_cast<int>(beyond.size()) < options.min_points_to_extend) return 0;
  // The second-farthest point: one stray sample does not stretch the lane.
  std::nth_element(beyond.begin(), beyond.end() - 2, beyond.end());
  const double reach = beyond[beyond.size() - 2];
  const double step_m = options.chord_spacing_m * horizontal;  // as the straight growth
  const int add = static_cast<int>(std::floor(reach / step_m + 0.5));
  if (add <= 0) return 0;
  cps->pop_back();  // the old phantom
  for (int k = 1; k <= add; ++k) {
    const double s = k * step_m, angle = s * curvature;
    const Eigen::Vector2d xy = end.head<2>() + t * (std::sin(angle) / curvature) +
                               l * ((1.0 - std::cos(angle)) / curvature);
    cps->emplace_back(xy.x(), xy.y(), end.z() + slope * s);
  }
  cps->push_back(2.0 * cps->back() - (*cps)[cps->size() - 2]);
  return add;
}

// Control point j as a linear function of the free real points: sum coeff * x[index] + constant.
struct Dependence {
  int index[2] = {-1, -1};
  double coeff[2] = {0.0, 0.0};
  Eigen::Vector3d constant = Eigen::Vector3d::Zero();
};

}  // namespace

std::vector<Eigen::Vector3d> FitLaneEnds(const std::vector<Eigen::Vector3d>& control_points,
                                         const std::vector<Eigen::Vector3d>& points,
                                         const LaneEndFitOptions& options, int* added_at_start,
                                         const std::vector<Eigen::Vector3d>* extension_points,
                                         const LaneEndCurvatures& curvatures) {
  if (control_points.size() < 4) {
    throw std::invalid_argument("FitLaneEnds needs at least 4 control points");
  }
  auto finite_of = [](const std::vector<Eigen::Vector3d>& in) {
    std::vector<Eigen::Vector3d> out;
    out.reserve(in.size());
    for (const Eigen::Vector3d& p : in) {
      if (p.allFinite()) out.push_back(p);
    }
    return out;
  };
  const std::vector<Eigen::Vector3d> finite = finite_of(points);
  const std::vector<Eigen::Vector3d> growth =
      extension_points ? finite_of(*extension_points) : finite;
  // 1. Grow both ends (the start by growing the reversed lane's end).
  std::vector<Eigen::Vector3d> cps = control_points;
  ExtendEnd(options, growth, curvatures.at_end, &cps);
  std::reverse(cps.begin(), cps.end());
  // Reversed, the start's curve turns the other way.
  const int at_start = ExtendEnd(options, growth, -curvatures.at_start, &cps);
  std::reverse(cps.begin(), cps.end());
  if (added_at_start) *added_at_start = at_start;

  // 2. Curve parameters of the points; the segments they fall on decide the free points.
  const int n = static_cast<int>(cps.size());
  // Closest points on the part of the curve near the points only (a lane can be kilometers
  // long; the points are its recent observations): segment k there is segment offset + k.
  std::vector<Eigen::Vector3d> all_points = finite;
  if (extension_points) all_points.insert(all_points.end(), growth.begin(), growth.end());
  std::size_t first = 0, last = cps.size() - 1;
  if (!ControlPointRangeNear(cps, all_points, options.max_point_distance_m + 5.0, &first, &last)) {
    first = 0;
    last = cps.size() - 1;
  }
  const int offset = static_cast<int>(first);
  const bool has_start = first == 0, has_end = last + 1 == cps.size();
  const CatmullRomSpline spline(
      std::vector<Eigen::Vector3d>(cps.begin() + first, cps.begin() + last + 1));
  struct Sample {
    int segment;
    Eigen::Vector4d basis;
    Eigen::Vector3d point;
    double prior_weight;  // the point set's weight
    double weight;        // times the Huber weight
  };
  std::vector<Sample> samples;
  std::vector<bool> free(n, false);
  auto add_samples = [&](const std::vector<Eigen::Vector3d>& set, double set_weight) {
    for (const Eigen::Vector3d& p : set) {
      const CatmullRomSpline::ClosestPoint closest = spline.FindClosest(p);
      if (closest.distance_m > options.max_point_distance_m) continue;
      const bool at_end =
          (has_start && closest.s <= 0.0) || (has_end && closest.s >= spline.NumSegments());
      if (at_end && closest.distance_m > kEndSnapM) continue;
      const int segment = offset + closest.segment;
      samples.push_back({segment, Basis(closest.u), p, set_weight, set_weight});
      for (int j = 0; j < 4; ++j) free[segment + j] = true;
    }
  };
  add_samples(finite, 1.0);
  // The growth points shape the new control points too (nothing else reaches them yet),
  // weakly, so that where `points` are they decide.
  if (extension_points) add_samples(growth, options.extension_weight);
  free[0] = free[n - 1] = false;  // phantoms follow their neighbors (recomputed at the end)
  std::vector<int> unknown_of(n, -1);
  std::vector<int> point_of;
  for (int j = 1; j < n - 1; ++j) {
    if (!free[j]) continue;
    unknown_of[j] = static_cast<int>(point_of.size());
    point_of.push_back(j);
  }
  const int m = static_cast<int>(point_of.size());
  if (m == 0) return cps;

  std::vector<Dependence> dep(n);
  for (int j = 0; j < n; ++j) {
    Dependence& d = dep[j];
    if (unknown_of[j] >= 0) {
      d.index[0] = unknown_of[j];
      d.coeff[0] = 1.0;
    } else if (j == 0 || j == n - 1) {
      // Phantom: 2 * (neighbor) - (next), each free or fixed.
      const int a = j == 0 ? 1 : n - 2, b = j == 0 ? 2 : n - 3;
      const int terms[2] = {a, b};
      const double factors[2] = {2.0, -1.0};
      for (int t = 0; t < 2; ++t) {
        if (unknown_of[terms[t]] >= 0) {
          d.index[t] = unknown_of[terms[t]];
          d.coeff[t] = factors[t];
        } else {
          d.constant += factors[t] * cps[terms[t]];
        }
      }
    } else {
      d.constant = cps[j];
    }
  }

  // Adds one linear row sum_j w_j c_(first + j) = target with weight `weight` (squared).
  Eigen::MatrixXd A(m, m);
  Eigen::MatrixXd b(m, 3);
  auto add_row = [&](int first, const double* w, int count, const Eigen::Vector3d& target,
                     double weight) {
    Eigen::Vector3d rhs = target;
    int idx[8];
    double val[8];
    int k = 0;
    for (int j = 0; j < count; ++j) {
      const Dependence& d = dep[first + j];
      rhs -= w[j] * d.constant;
      for (int t = 0; t < 2; ++t) {
        if (d.index[t] < 0) continue;
        idx[k] = d.index[t];
        val[k] = w[j] * d.coeff[t];
        ++k;
      }
    }
    for (int r = 0; r < k; ++r) {
      for (int c = 0; c < k; ++c) A(idx[r], idx[c]) += weight * val[r] * val[c];
      b.row(idx[r]) += weight * val[r] * rhs.transpose();
    }
  };

  Eigen::MatrixXd x(m, 3);
  for (int k = 0; k < m; ++k) x.row(k) = cps[point_of[k]].transpose();
  const double prior_weight = 1.0 / (options.prior_sigma_m * options.prior_sigma_m);
  const double second_difference[3] = {1.0, -2.0, 1.0};
  for (int round = 0; round < kReweightRounds; ++round) {
    A.setZero();
    b.setZero();
    for (const Sample& s : samples) add_row(s.segment, s.basis.data(), 4, s.point, s.weight);
    for (int j = 1; j + 1 < n; ++j) {
      if (!free[j - 1] && !free[j] && !free[j + 1]) continue;
      add_row(j - 1, second_difference, 3, Eigen::Vector3d::Zero(), options.smoothness_weight);
    }
    for (int k = 0; k < m; ++k) {
      A(k, k) += prior_weight;
      b.row(k) += prior_weight * cps[point_of[k]].transpose();
    }
    x = A.ldlt().solve(b);
    if (!x.allFinite()) return cps;  // degenerate: keep the extended lane as it was
    // Huber weights from the residuals at the new estimate.
    for (Sample& s : samples) {
      Eigen::Vector3d fit = Eigen::Vector3d::Zero();
      for (int j = 0; j < 4; ++j) {
        const Dependence& d = dep[s.segment + j];
        Eigen::Vector3d c = d.constant;
        for (int t = 0; t < 2; ++t) {
          if (d.index[t] >= 0) c += d.coeff[t] * x.row(d.index[t]).transpose();
        }
        fit += s.basis(j) * c;
      }
      const double r = (fit - s.point).norm();
      s.weight = s.prior_weight * (r <= options.robust_scale_m ? 1.0 : options.robust_scale_m / r);
    }
  }
  for (int k = 0; k < m; ++k) cps[point_of[k]] = x.row(k).transpose();
  if (free[1] || free[2]) cps.front() = 2.0 * cps[1] - cps[2];
  if (free[n - 2] || free[n - 3]) cps.back() = 2.0 * cps[n - 2] - cps[n - 3];
  return cps;
}

void FitLaneEndsNear(const LaneEndFitOptions& options, const std::vector<Eigen::Vector3d>& points,
                     const std::vector<Eigen::Vector3d>& extension_points,
                     std::vector<Eigen::Vector3d>* cps, int* added_at_start,
                     std::size_t* first_changed, const LaneEndCurvatures& curvatures) {
  std::vector<Eigen::Vector3d> near = points;
  near.insert(near.end(), extension_points.begin(), extension_points.end());
  near.erase(std::remove_if(near.begin(), near.end(),
                            [](const Eigen::Vector3d& p) { return !p.allFinite(); }),
             near.end());
  std::size_t first = 0, last = cps->size() - 1;
  if (!near.empty() && ControlPointRangeNear(*cps, near, kSliceReachM, &first, &last)) {
    first = first > kSliceMarginPoints ? first - kSliceMarginPoints : 0;
    last = std::min(cps->size() - 1, last + kSliceMarginPoints);
  } else {
    first = 0;
    last = cps->size() - 1;
  }
  const std::vector<Eigen::Vector3d> slice(cps->begin() + first, cps->begin() + last + 1);
  int added = 0;
  std::vector<Eigen::Vector3d> fitted =
      FitLaneEnds(slice, points, options, &added, &extension_points, curvatures);
  const bool starts_inside = first > 0, ends_inside = last + 1 < cps->size();
  // A slice end inside the lane must come back as it was (else: the whole lane, as before).
  if ((starts_inside && (added != 0 || fitted.front() != slice.front())) ||
      (ends_inside && (fitted.size() != slice.size() + static_cast<std::size_t>(added) ||
                       fitted.back() != slice.back()))) {
    *cps = FitLaneEnds(*cps, points, options, added_at_start, &extension_points, curvatures);
    if (first_changed) *first_changed = 0;
    return;
  }
  *added_at_start = added;
  if (first_changed) *first_changed = first;  // nothing before the slice moved
  const std::size_t old_size = slice.size();
  if (fitted.size() == old_size) {
    std::copy(fitted.begin(), fitted.end(), cps->begin() + first);
  } else {
    cps->erase(cps->begin() + first, cps->begin() + last + 1);
    cps->insert(cps->begin() + first, fitted.begin(), fitted.end());
  }
}

}  // namespace ipm_road_mapper
