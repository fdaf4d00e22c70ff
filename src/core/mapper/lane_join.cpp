#include "ipm_road_mapper/core/mapper/lane_join.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>

#include "ipm_road_mapper/core/geometry/catmull_rom_spline.h"
#include "ipm_road_mapper/core/geometry/principal_axis.h"
#include "ipm_road_mapper/core/map/index_ranges.h"
#include "ipm_road_mapper/core/mapper/lane_unmeasured.h"
#include "ipm_road_mapper/core/mapper/shared_frames.h"

namespace ipm_road_mapper {
namespace {

// Each end is modelled by at most this many observations (the latest at an end, the
// earliest at a start): the ones that shaped it.
constexpr std::size_t kMaxEndObservations = 60;
// Curvature prior of an end model: c = kappa / 2, kappa within this (1/m) of the curvature
// of the lane's own control points there.
constexpr double kCurvatureSigma = 0.01;
// The two ends must point within this angle of each other before they are compared.
constexpr double kMinDirectionCos = 0.87;  // 30 deg

// A horizontal frame at the junction: origin, x along the pair's mean direction, y left.
struct PairFrame {
  Eigen::Vector2d origin = Eigen::Vector2d::Zero();
  Eigen::Vector2d x_axis = Eigen::Vector2d::UnitX();
  Eigen::Vector2d Local(const Eigen::Vector3d& p_map) const {
    const Eigen::Vector2d d = p_map.head<2>() - origin;
    return {d.dot(x_axis), x_axis.x() * d.y() - x_axis.y() * d.x()};
  }
  Eigen::Vector2d Map(double x, double y) const {
    return origin + x * x_axis + y * Eigen::Vector2d(-x_axis.y(), x_axis.x());
  }
};

// y(x) = coeff . (1, x, x^2) with its covariance (m^2 units).
struct EndModel {
  Eigen::Vector3d coeff = Eigen::Vector3d::Zero();
  Eigen::Matrix3d cov = Eigen::Matrix3d::Identity();
  double x_min = 0.0, x_max = 0.0;  // extent of its data along the frame
  double Offset(double x) const { return coeff.dot(Eigen::Vector3d(1.0, x, x * x)); }
  double Slope(double x) const { return coeff.y() + 2.0 * coeff.z() * x; }
};

// The mean lateral IPM variance (across the pair frame's x axis, Omega_p) of the kept
// selected points of one measurement (indices into its selected points). Omega_p is in
// base_link: the frame's yaw (map <- base) is read from the selected points in base_link
// and in the map. 0 when the measurement carries no points (lanes built without them).
double LateralIpmVariance(const LaneMeasurement& m, const std::vector<std::size_t>& kept_index,
                          const PairFrame& frame) {
  std::vector<std::size_t> sel;
  for (std::size_t i = 0; i < m.points.size(); ++i) {
    if (m.selected[i]) sel.push_back(i);
  }
  if (sel.size() != m.selected_map.size() || sel.size() < 2 || kept_index.empty()) return 0.0;
  const Eigen::Vector2d d_base =
      (m.points[sel.back()].p_base - m.points[sel.front()].p_base).head<2>();
  const Eigen::Vector2d d_map = (m.selected_map.back() - m.selected_map.front()).head<2>();
  if (d_base.norm() < 1e-6 || d_map.norm() < 1e-6) return 0.0;
  const double yaw =
      std::atan2(d_map.y(), d_map.x()) - std::atan2(d_base.y(), d_base.x());  // map <- base
  const Eigen::Vector2d normal_map(-frame.x_axis.y(), frame.x_axis.x());
  const Eigen::Vector2d normal_base(
      std::cos(yaw) * normal_map.x() + std::sin(yaw) * normal_map.y(),
      -std::sin(yaw) * normal_map.x() + std::cos(yaw) * normal_map.y());
  double sum = 0.0;
  for (std::size_t k : kept_index) {
    sum += normal_base.dot(m.points[sel[k]].cov_base * normal_base);
  }
  return sum / static_cast<double>(kept_index.size());
}

// The data near one end of `lane` in `frame`, each observation weighted once in total: the
// selected points of its latest (at_end) or earliest observations within end_length_m of
// the end's data; the real control points there when fewer than two observations remain
// (histories are pruned on long drives). Each observation's sigma: the floor and its points'
// lateral Omega_p, the latter times join.ipm_correlation_frames (the body's pitch, most of
// Omega_p, moves the points of consecutive frames together: docs/backend.md).
void EndData(const LaneElement& lane, bool at_end, const PairFrame& frame,
             const LaneJoinOptions& join, double floor_sigma_m,
             std::vector<Eigen::Vector3d>* points, std::vector<double>* weights,
             std::vector<double>* sigmas) {
  const double end_length_m = join.end_length_m;
  const std::vector<Eigen::Vector3d>& cps = lane.control_points_map;
  const Eigen::Vector3d end_cp = at_end ? cps[cps.size() - 2] : cps[1];
  std::vector<const LaneMeasurement*> ms;
  for (std::size_t k = 0; k < lane.history.size() && ms.size() < kMaxEndObservations; ++k) {
    ms.push_back(&lane.history[at_end ? lane.history.size() - 1 - k : k]);
  }
  // The end of the data: the extreme x among the points near the end control point.
  const double reach = 2.0 * end_length_m;
  double extreme =
      at_end ? -std::numeric_limits<double>::infinity() : std::numeric_limits<double>::infinity();
  for (const LaneMeasurement* m : ms) {
    for (const Eigen::Vector3d& p : m->selected_map) {
      if ((p - end_cp).head<2>().norm() > reach) continue;
      const double x = frame.Local(p).x();
      extreme = at_end ? std::max(extreme, x) : std::min(extreme, x);
    }
  }
  int observations = 0;
  if (std::isfinite(extreme)) {
    for (const LaneMeasurement* m : ms) {
      std::vector<Eigen::Vector3d> kept;
      std::vector<std::size_t> kept_index;
      for (std::size_t k = 0; k < m->selected_map.size(); ++k) {
        const Eigen::Vector3d& p = m->selected_map[k];
        if ((p - end_cp).head<2>().norm() > reach) continue;
        const double x = frame.Local(p).x();
        if (std::abs(x - extreme) <= end_length_m) {
          kept.push_back(p);
          kept_index.push_back(k);
        }
      }
      if (kept.empty()) continue;
      ++observations;
      const double lateral_variance = LateralIpmVariance(*m, kept_index, frame);
      for (const Eigen::Vector3d& p : kept) {
        points->push_back(p);
        weights->push_back(1.0 / static_cast<double>(kept.size()));
        sigmas->push_back(lateral_variance);  // made a sigma below
      }
    }
  }
  // Fewer observations than the correlation length: together they know the line no worse
  // than one of them.
  const double correlated =
      std::min(join.ipm_correlation_frames, static_cast<double>(observations));
  for (double& sigma : *sigmas) {
    sigma = std::sqrt(floor_sigma_m * floor_sigma_m + correlated * sigma);
  }
  if (observations >= 2) return;
  points->clear();
  weights->clear();
  sigmas->clear();
  for (std::size_t j = 1; j + 1 < cps.size(); ++j) {
    if ((cps[j] - end_cp).head<2>().norm() <= end_length_m) {
      points->push_back(cps[j]);
      weights->push_back(1.0);
      sigmas->push_back(floor_sigma_m);
    }
  }
}

// Weighted least squares of y(x) = a + b x + c x^2 with per-point sigmas; two Huber rounds
// (scale 2 sigma) so that one stray observation does not bend the end.
std::optional<EndModel> FitEndModel(const std::vector<Eigen::Vector3d>& points,
                                    const std::vector<double>& weights,
                                    const std::vector<double>& sigmas, const PairFrame& frame,
                                    double kappa) {
  if (points.size() < 2) return std::nullopt;
  EndModel model;
  model.x_min = std::numeric_limits<double>::infinity();
  model.x_max = -model.x_min;
  std::vector<Eigen::Vector2d> xy;
  for (const Eigen::Vector3d& p : points) {
    xy.push_back(frame.Local(p));
    model.x_min = std::min(model.x_min, xy.back().x());
    model.x_max = std::max(model.x_max, xy.back().x());
  }
  std::vector<double> robust(points.size(), 1.0);
  Eigen::Matrix3d N;
  for (int round = 0; round < 3; ++round) {
    N = Eigen::Matrix3d::Zero();
    Eigen::Vector3d b = Eigen::Vector3d::Zero();
    for (std::size_t i = 0; i < xy.size(); ++i) {
      const Eigen::Vector3d row(1.0, xy[i].x(), xy[i].x() * xy[i].x());
      const double w = weights[i] * robust[i] / (sigmas[i] * sigmas[i]);
      N += w * row * row.transpose();
      b += w * row * xy[i].y();
    }
    const double curvature_weight = 1.0 / std::pow(0.5 * kCurvatureSigma, 2);
    N(2, 2) += curvature_weight;
    b(2) += curvature_weight * 0.5 * kappa;
    N(0, 0) += 1e-9;
    N(1, 1) += 1e-9;
    model.coeff = N.ldlt().solve(b);
    if (!model.coeff.allFinite()) return std::nullopt;
    for (std::size_t i = 0; i < xy.size(); ++i) {
      const double r = std::abs(model.Offset(xy[i].x()) - xy[i].y());
      robust[i] = r <= 2.0 * sigmas[i] ? 1.0 : 2.0 * sigmas[i] / r;
    }
  }
  model.cov = N.inverse();
  if (!model.cov.allFinite()) return std::nullopt;
  return model;
}

// Everything a join decision and a join need.
struct PairAnalysis {
  PairFrame frame;
  EndModel first, second;               // first's end, second's start
  std::vector<Eigen::Vector3d> points;  // the data of both ends (map frame)
  double x_meet = 0.0;                  // middle of the gap (or overlap)
};

std::optional<PairAnalysis> Analyze(const LaneElement& first, const LaneElement& second,
                                    const LaneJoinOptions& join,
                                    const AssociationOptions& options) {
  if (first.class_id != second.class_id || first.control_points_map.size() < 4 ||
      second.control_points_map.size() < 4) {
    return std::nullopt;
  }
  // The directions at the very ends (a chord): over longer stretches an arc turns too much.
  const Eigen::Vector2d t_first = LaneEndDirection(first.control_points_map, true, 0.0);
  const Eigen::Vector2d t_second = LaneEndDirection(second.control_points_map, false, 0.0);
  if (t_first.dot(t_second) < kMinDirectionCos) return std::nullopt;
  PairAnalysis a;
  a.frame.origin = first.control_points_map[first.control_points_map.size() - 2].head<2>();
  a.frame.x_axis = (t_first + t_second).normalized();
  const double sigma = LaneFloorSigma(options);
  std::vector<Eigen::Vector3d> points_first, points_second;
  std::vector<double> weights_first, weights_second, sigmas_first, sigmas_second;
  EndData(first, true, a.frame, join, sigma, &points_first, &weights_first, &sigmas_first);
  EndData(second, false, a.frame, join, sigma, &points_second, &weights_second, &sigmas_second);
  const auto model_first =
      FitEndModel(points_first, weights_first, sigmas_first, a.frame,
                  LaneEndCurvature(first.control_points_map, true, join.end_length_m));
  const auto model_second =
      FitEndModel(points_second, weights_second, sigmas_second, a.frame,
                  LaneEndCurvature(second.control_points_map, false, join.end_length_m));
  if (!model_first || !model_second) return std::nullopt;
  a.first = *model_first;
  a.second = *model_second;
  const double gap = a.second.x_min - a.first.x_max;
  if (gap > join.max_gap_m || gap < -join.max_overlap_m) return std::nullopt;
  // Second must continue first, not lie behind or inside it.
  if (a.second.x_max <= a.first.x_max || a.second.x_min <= a.first.x_min) return std::nullopt;
  a.x_meet = 0.5 * (a.first.x_max + a.second.x_min);
  a.points = points_first;
  a.points.insert(a.points.end(), points_second.begin(), points_second.end());
  return a;
}

// `first` with `cps` as its control points, those with `unmeasured` set unmeasured, and
// `second`'s observations merged in.
LaneElement Joined(const LaneElement& first, const LaneElement& second,
                   std::vector<Eigen::Vector3d> cps, const std::vector<bool>& unmeasured) {
  LaneElement joined = first;
  joined.control_points_map = std::move(cps);
  joined.unmeasured_cps = RangesOfFlags(unmeasured, first.first_cp_index);
  MergeObservations(second, &joined);
  joined.optimized = first.optimized || second.optimized;
  joined.retired_before_frame = std::min(first.retired_before_frame, second.retired_before_frame);
  return joined;
}

}  // namespace

Eigen::Vector2d LaneEndDirection(const std::vector<Eigen::Vector3d>& cps, bool at_end,
                                 double length_m) {
  const int n = static_cast<int>(cps.size());
  const int end = at_end ? n - 2 : 1;
  const int step = at_end ? -1 : 1;
  int other = end + step;
  while (other + step >= 1 && other + step <= n - 2 &&
         (cps[other].head<2>() - cps[end].head<2>()).norm() < length_m) {
    other += step;
  }
  Eigen::Vector2d d =
      at_end ? (cps[end] - cps[other]).head<2>().eval() : (cps[other] - cps[end]).head<2>().eval();
  return d.norm() > 1e-9 ? d.normalized() : Eigen::Vector2d::Zero();
}

void MergeObservations(const LaneElement& other, LaneElement* lane) {
  lane->history.insert(lane->history.end(), other.history.begin(), other.history.end());
  std::sort(lane->history.begin(), lane->history.end(),
            [](const LaneMeasurement& x, const LaneMeasurement& y) {
              return x.frame_index < y.frame_index;
            });
  lane->pruned += other.pruned;
  lane->first_frame = std::min(lane->first_frame, other.first_frame);
  lane->last_frame = std::max(lane->last_frame, other.last_frame);
  lane->first_seen = std::min(lane->first_seen, other.first_seen);
  lane->last_seen = std::max(lane->last_seen, other.last_seen);
}

namespace {

// Whether two instances of one frame are two lines: side by side (overlapping along their
// common direction by more than kSideBySideOverlapM) or not on one line (their means more
// than kCollinearOffsetM apart across it: staggered lines, a lane shift). The direction is
// the mean of each set's own principal direction (the union's would be across two short
// pieces of parallel lines). Either without extent: two lines (nothing tells them apart).
bool TwoLinesInOneFrame(const std::vector<Eigen::Vector3d>& a,
                        const std::vector<Eigen::Vector3d>& b) {
  const PrincipalAxis pa = HorizontalPrincipalAxis(a), pb = HorizontalPrincipalAxis(b);
  if (!(pa.scatter > 0.0) || !(pb.scatter > 0.0)) return true;
  const Eigen::Vector2d& da = pa.direction;
  const Eigen::Vector2d db = pa.direction.dot(pb.direction) < 0.0 ? -pb.direction : pb.direction;
  const Eigen::Vector2d along = (da + db).normalized();
  const Eigen::Vector2d across(-along.y(), along.x());
  const auto extent = [&](const std::vector<Eigen::Vector3d>& set) {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo, mean_across = 0.0;
    for (const Eigen::Vector3d& p : set) {
      lo = std::min(lo, p.head<2>().dot(along));
      hi = std::max(hi, p.head<2>().dot(along));
      mean_across += p.head<2>().dot(across);
    }
    return std::make_tuple(lo, hi, mean_across / static_cast<double>(set.size()));
  };
  const auto [a_lo, a_hi, a_across] = extent(a);
  const auto [b_lo, b_hi, b_across] = extent(b);
  const double overlap = std::min(a_hi, b_hi) - std::max(a_lo, b_lo);
  return overlap > kSideBySideOverlapM || std::abs(b_across - a_across) > kCollinearOffsetM;
}

}  // namespace

bool CoObserved(const LaneElement& a, const LaneElement& b) {
  return AnySharedFrame(a, b, [](const LaneMeasurement& ma, const LaneMeasurement& mb) {
    return TwoLinesInOneFrame(ma.selected_map, mb.selected_map);
  });
}

bool LaneContinues(const LaneElement& first, const LaneElement& second, const LaneJoinOptions& join,
                   const AssociationOptions& options) {
  return LaneJoinCost(first, second, join, options) >= 0.0;
}

double LaneJoinCost(const LaneElement& first, const LaneElement& second,
                    const LaneJoinOptions& join, const AssociationOptions& options,
                    bool* co_observed) {
  const bool two_lines = CoObserved(first, second);
  if (co_observed) *co_observed = two_lines;
  if (two_lines) return -1.0;
  const auto a = Analyze(first, second, join, options);
  if (!a) return -1.0;
  const double x = a->x_meet;
  const Eigen::Vector3d J(1.0, x, x * x), dJ(0.0, 1.0, 2.0 * x);
  const double offset = a->first.Offset(x) - a->second.Offset(x);
  const double slope = a->first.coeff.dot(dJ) - a->second.coeff.dot(dJ);
  const double floor2 = options.lane_position_sigma_m * options.lane_position_sigma_m;
  const double var_offset = J.dot(a->first.cov * J) + J.dot(a->second.cov * J) + 2.0 * floor2;
  const double var_slope = dJ.dot(a->first.cov * dJ) + dJ.dot(a->second.cov * dJ) +
                           2.0 * floor2 / (join.end_length_m * join.end_length_m);
  const double cost =
      std::max(std::abs(offset) / std::sqrt(var_offset), std::abs(slope) / std::sqrt(var_slope));
  return cost <= join.gate_sigmas ? cost : -1.0;
}

std::optional<LaneElement> JoinLanes(const LaneElement& first, const LaneElement& second,
                                     const LaneJoinOptions& join, const AssociationOptions& options,
                                     double chord_spacing_m) {
  const auto a = Analyze(first, second, join, options);
  if (!a) return std::nullopt;
  const double x_first_end = std::min(a->first.x_max, a->x_meet);
  const double x_second_start = std::max(a->second.x_min, a->x_meet);
  const std::vector<Eigen::Vector3d>& cf = first.control_points_map;
  const std::vector<Eigen::Vector3d>& cs = second.control_points_map;
  // Each kept point keeps its lane's flag (lane_unmeasured.h); the bridge's points are
  // interpolated, measured by no pixel.
  std::vector<Eigen::Vector3d> cps = {cf.front()};  // first's phantom start
  std::vector<bool> unmeasured = {false};
  for (std::size_t j = 1; j + 1 < cf.size(); ++j) {
    if (a->frame.Local(cf[j]).x() <= x_first_end) {
      cps.push_back(cf[j]);
      unmeasured.push_back(ControlPointUnmeasured(first, j));
    }
  }
  std::vector<Eigen::Vector3d> tail;
  std::vector<bool> tail_unmeasured;
  for (std::size_t j = 1; j + 1 < cs.size(); ++j) {
    if (a->frame.Local(cs[j]).x() >= x_second_start) {
      tail.push_back(cs[j]);
      tail_unmeasured.push_back(ControlPointUnmeasured(second, j));
    }
  }
  if (cps.size() < 2 || tail.empty()) return std::nullopt;
  // The bridge: a cubic (Hermite) from first's last kept control point to second's first,
  // with the end models' directions there; z linear between them.
  const Eigen::Vector3d from = cps.back(), to = tail.front();
  const Eigen::Vector2d la = a->frame.Local(from), lb = a->frame.Local(to);
  const double length = lb.x() - la.x();
  const int inserted =
      length > 0.0 ? std::max(0, static_cast<int>(std::lround(length / chord_spacing_m)) - 1) : 0;
  const double slope_a = a->first.Slope(la.x()), slope_b = a->second.Slope(lb.x());
  for (int k = 1; k <= inserted; ++k) {
    const double t = static_cast<double>(k) / (inserted + 1);
    const double h00 = 2 * t * t * t - 3 * t * t + 1, h10 = t * t * t - 2 * t * t + t;
    const double h01 = -2 * t * t * t + 3 * t * t, h11 = t * t * t - t * t;
    const double y = h00 * la.y() + h10 * length * slope_a + h01 * lb.y() + h11 * length * slope_b;
    const Eigen::Vector2d p = a->frame.Map(la.x() + t * length, y);
    cps.emplace_back(p.x(), p.y(), (1.0 - t) * from.z() + t * to.z());
    unmeasured.push_back(true);
  }
  cps.insert(cps.end(), tail.begin(), tail.end());
  unmeasured.insert(unmeasured.end(), tail_unmeasured.begin(), tail_unmeasured.end());
  cps.push_back(2.0 * cps.back() - cps[cps.size() - 2]);
  unmeasured.push_back(false);
  if (cps.size() < 4) return std::nullopt;

  return Joined(first, second, std::move(cps), unmeasured);
}

std::optional<LaneElement> JoinLanesThrough(const LaneElement& first, const LaneElement& second,
                                            const std::vector<Eigen::Vector3d>& bridge_map,
                                            std::size_t first_end_dropped,
                                            std::size_t second_start_dropped) {
  const std::vector<Eigen::Vector3d>& cf = first.control_points_map;
  const std::vector<Eigen::Vector3d>& cs = second.control_points_map;
  if (cf.size() < 4 + first_end_dropped || cs.size() < 4 + second_start_dropped) {
    return std::nullopt;
  }
  // Without first's end phantom and dropped points, without second's start phantom and dropped.
  const auto first_to = cf.end() - 1 - static_cast<std::ptrdiff_t>(first_end_dropped);
  const auto second_from = cs.begin() + 1 + static_cast<std::ptrdiff_t>(second_start_dropped);
  std::vector<Eigen::Vector3d> cps(cf.begin(), first_to);
  std::vector<bool> unmeasured;
  for (std::size_t j = 0; j < cps.size(); ++j) {
    unmeasured.push_back(ControlPointUnmeasured(first, j));
  }
  // The bridge's points: no pixel measured them (no frame saw the gap).
  cps.insert(cps.end(), bridge_map.begin(), bridge_map.end());
  unmeasured.resize(cps.size(), true);
  for (auto it = second_from; it != cs.end() - 1; ++it) {
    cps.push_back(*it);
    unmeasured.push_back(ControlPointUnmeasured(second, it - cs.begin()));
  }
  cps.push_back(2.0 * cps.back() - cps[cps.size() - 2]);
  unmeasured.push_back(false);
  return Joined(first, second, std::move(cps), unmeasured);
}

}  // namespace ipm_road_mapper
