// Internal to SolveWindow: the cross-validation of a refined extrinsic against the rough one
// it started from (the final global solve's; docs/backend.md, "The drive's calibration").
//
// The extrinsic is one constant of the whole drive, so independent parts of the data must
// find the same correction. A pull that one stretch of the drive or one element makes (an
// unobserved direction carried by noise, the slow alternation along the lever arm, a wrong
// lane or marking) does not repeat in the other half. So the map + extrinsic step is re-run
// on each half of the span (by frame index, the other half held out), from the solved
// state, with its own observability. In the whitened eigen-directions of the whole's
// information (extrinsic_observability.h) a direction keeps its refined value only when the
// data knows it at least as well as the mounting prior, both halves observe it, and they
// agree: both move it from the rough value the same way as the whole, and by more than they
// differ. The other directions go back to the rough value, the map and poses are re-fit with
// that extrinsic held, and the confirmed directions are the calibration's observed ones. A
// bias that both halves share (the roll on the hilly drives) passes: this check catches
// what varies, not what is systematic.
#pragma once

#include <array>
#include <vector>

#include "ipm_road_mapper/core/backend/window_state.h"

namespace ipm_road_mapper {
namespace window_solve {

// One part of the data's answer: its whitened correction from the rough extrinsic
// (delta / prior sigma) and its whitened information (S H S).
struct PartEstimate {
  Vector6d w = Vector6d::Zero();
  Matrix6d information_whitened = Matrix6d::Zero();
};

// Whether each eigen-direction k (ExtrinsicObservability::basis_whitened column k) is
// confirmed by the splits (pairs of disjoint parts), see the file comment: the whole's
// eigenvalue is at least min_information_ratio, and a part observes direction v when
// v^T information_whitened v >= min_information_ratio / 2 (it holds about half the data).
std::array<bool, 6> ConfirmedDirections(const ExtrinsicObservability& observability,
                                        const Vector6d& w_full,
                                        const std::vector<std::array<PartEstimate, 2>>& splits,
                                        double min_information_ratio);

// The lever arm (x, y: whitened axes 3, 4 of w) moves only where its shift stands out of
// its own uncertainty: an axis whose |w_i| is below min_shift_sigmas of its marginal
// posterior sigma sqrt(C_ii), C = V (Lambda + 1)^-1 V^T (data plus the mounting prior, in
// prior-whitened units), goes back to the rough value. The lever arm is seen only through
// the motion; a shift the data cannot tell from noise is more likely a pull of the map than
// a calibration. The height (axis 5) is not tested alone: it is observed with the pitch, and
// holding it at the rough value while the pitch keeps its refinement spoils the homography
// they set together (public_road seed 3: IPM grid 0.044 -> 0.074 m). The pair is left to
// the eigen-directions of the cross-validation, which carry their correlation. A held axis
// is no longer reported observed (axis_observed). Returns how many axes it held.
int HoldInsignificantTranslation(double min_shift_sigmas, ExtrinsicObservability* observability,
                                 Vector6d* w);

// The cross-validation (see the file comment) of the state after a solve: directions that
// are not confirmed go back to the prior's center (the rough extrinsic), and the map and
// poses are re-fit with the extrinsic held there. Returns how many observed directions it
// sent back (0: the refined extrinsic stands as it is).
int CrossValidateExtrinsic(const WindowSnapshot& snapshot, const BackendOptions& options,
                           double time_limit_s, WindowState* state);

}  // namespace window_solve
}  // namespace ipm_road_mapper
