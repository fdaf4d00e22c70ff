#include "ipm_road_mapper/core/backend/window_extrinsic_validation.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include "ipm_road_mapper/core/backend/window_extrinsic.h"
#include "ipm_road_mapper/core/backend/window_map_step.h"
#include "ipm_road_mapper/core/backend/window_pose_step.h"

namespace ipm_road_mapper {
namespace window_solve {
namespace {

// A direction is a candidate when the drive's data knows it at least as well as the mounting
// prior does (whitened information >= 1; a window's flags ask for 4,
// extrinsic_min_information_ratio): the halves, not the ratio, then decide. The lever arm
// on a drive with turns (port: 2.2-2.4) is such a direction, and its refinement was right
// there when the halves agreed.
constexpr double kCandidateInformationRatio = 1.0;

// A lever-arm shift smaller than this many of its sigmas is not told from the rough value's
// error (a two-sided test at about 95 %; HoldInsignificantTranslation).
constexpr double kMinTranslationShiftSigmas = 2.0;

// Re-solves the map + extrinsic step on one half of the state's frames (0: those before the
// middle frame, 1: from it on), from the solved state; nothing when the half has no data or
// its solve is not usable.
std::optional<PartEstimate> EstimateHalf(const WindowSnapshot& snapshot,
                                         const BackendOptions& options, const WindowState& state,
                                         int half, double time_limit_s) {
  WindowState sub = state;
  const std::size_t middle = snapshot.frames[snapshot.frames.size() / 2].index;
  for (std::size_t i = 0; i < snapshot.frames.size(); ++i) {
    sub.held_out[i] = (snapshot.frames[i].index >= middle) == (half == 0);
  }
  sub.hold_out = true;
  sub.observability_valid = false;
  ObserveExtrinsic(snapshot, options, &sub);
  if (!sub.observability_valid) return std::nullopt;
  sub.step_time_limit_s = time_limit_s;
  int blocks = 0;
  const ceres::Solver::Summary summary = MapStep(snapshot, options, &sub, &blocks);
  if (blocks == 0 || !summary.IsSolutionUsable()) return std::nullopt;
  const Vector6d sigma = state.observability.prior_sigma;
  PartEstimate estimate;
  estimate.w = snapshot.extrinsic_prior.DeltaOf(sub.extrinsic.ToIsometry()).cwiseQuotient(sigma);
  estimate.information_whitened =
      sigma.asDiagonal() * sub.observability.information * sigma.asDiagonal();
  return estimate;
}

}  // namespace

std::array<bool, 6> ConfirmedDirections(const ExtrinsicObservability& observability,
                                        const Vector6d& w_full,
                                        const std::vector<std::array<PartEstimate, 2>>& splits,
                                        double min_information_ratio) {
  std::array<bool, 6> confirmed{};
  for (int k = 0; k < 6; ++k) {
    if (observability.eigenvalues(k) < min_information_ratio) continue;
    const Vector6d& v = observability.basis_whitened.col(k);
    const double a_full = v.dot(w_full);
    int votes = 0;
    bool disagreed = false;
    for (const auto& split : splits) {
      const bool both_observe = std::all_of(split.begin(), split.end(), [&](const auto& part) {
        return v.dot(part.information_whitened * v) >= 0.5 * min_information_ratio;
      });
      if (!both_observe) continue;  // this split cannot tell
      ++votes;
      const double a = v.dot(split[0].w), b = v.dot(split[1].w);
      const bool same_way = a * a_full > 0.0 && b * a_full > 0.0;
      disagreed = disagreed || !same_way || std::abs(a - b) >= std::min(std::abs(a), std::abs(b));
    }
    confirmed[k] = votes > 0 && !disagreed;
  }
  return confirmed;
}

int HoldInsignificantTranslation(double min_shift_sigmas, ExtrinsicObservability* observability,
                                 Vector6d* w) {
  const Vector6d inverse = (observability->eigenvalues.array() + 1.0).inverse().matrix();
  const Matrix6d covariance = observability->basis_whitened * inverse.asDiagonal() *
                              observability->basis_whitened.transpose();
  int held = 0;
  for (int i = 3; i <= 4; ++i) {  // x, y; never the height alone (header)
    if ((*w)(i) == 0.0 || std::abs((*w)(i)) >= min_shift_sigmas * std::sqrt(covariance(i, i)))
      continue;
    (*w)(i) = 0.0;
    observability->axis_observed[i] = false;  // held at the rough value: not calibrated
    ++held;
  }
  return held;
}

int CrossValidateExtrinsic(const WindowSnapshot& snapshot, const BackendOptions& options,
                           double time_limit_s, WindowState* state) {
  if (!state->observability_valid || state->extrinsic_frozen || snapshot.frames.size() < 2) {
    return 0;
  }
  const Vector6d sigma = state->observability.prior_sigma;
  const Vector6d w_full =
      snapshot.extrinsic_prior.DeltaOf(state->extrinsic.ToIsometry()).cwiseQuotient(sigma);
  // The split: the two halves in time. (Markings against lanes, each re-solved from the
  // solved state, was measured as a second split: it agreed where the halves did on the
  // hilly drives and sent back port's well-refined rotation, 0.08 -> 0.19 deg.)
  const double part_time_s = time_limit_s / 6.0;
  std::vector<std::array<PartEstimate, 2>> splits;
  const auto first = EstimateHalf(snapshot, options, *state, 0, part_time_s);
  const auto second = EstimateHalf(snapshot, options, *state, 1, part_time_s);
  if (first && second) splits.push_back({*first, *second});
  const std::array<bool, 6> confirmed =
      ConfirmedDirections(state->observability, w_full, splits, kCandidateInformationRatio);
  Vector6d w_kept = Vector6d::Zero();
  int sent_back = 0;
  for (int k = 0; k < 6; ++k) {
    const Vector6d& v = state->observability.basis_whitened.col(k);
    if (confirmed[k]) {
      w_kept += v.dot(w_full) * v;
    } else if (state->observability.eigenvalues(k) >= kCandidateInformationRatio) {
      ++sent_back;
    }
  }
  state->observability.observed = confirmed;  // what the drive's calibration stands on
  state->observability.CountObserved();
  HoldInsignificantTranslation(kMinTranslationShiftSigmas, &state->observability, &w_kept);
  if ((w_kept - w_full).norm() == 0.0) return sent_back;
  // The kept extrinsic, held while the map and the poses follow it.
  state->extrinsic = PoseBlocks(snapshot.extrinsic_prior.FromDelta(w_kept.cwiseProduct(sigma)));
  state->extrinsic_frozen = true;
  state->step_time_limit_s = time_limit_s / 6.0;
  int blocks = 0;
  MapStep(snapshot, options, state, &blocks);
  if (options.pose_update) PoseStep(snapshot, options, state, &blocks);
  state->extrinsic_frozen = false;  // validated, not refused: its calibration stands
  return sent_back;
}

}  // namespace window_solve
}  // namespace ipm_road_mapper
