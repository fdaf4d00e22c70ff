// The cross-validation of the refined extrinsic (window_extrinsic_validation.h): a direction
// keeps its refinement only when independent parts of the data (the halves in time; any
// other split) each observe it and agree on it; a lever-arm shift inside its own sigmas is
// held, never the height alone; and ExtrinsicObservability::CountObserved.
#include <gtest/gtest.h>

#include "ipm_road_mapper/core/backend/extrinsic_observability.h"
#include "ipm_road_mapper/core/backend/window_extrinsic_validation.h"

namespace ipm_road_mapper {
namespace window_solve {
namespace {

// Roll, yaw and z well observed (whitened information 100), the rest not.
ExtrinsicObservability RollYawZObserved() {
  Matrix6d H = Matrix6d::Zero();
  H(0, 0) = H(2, 2) = H(5, 5) = 100.0;
  H(1, 1) = H(3, 3) = H(4, 4) = 0.5;
  return AnalyzeObservability(H, Vector6d::Ones(), 4.0);
}

// The eigen-direction of `o` along chart axis i.
int DirectionOf(const ExtrinsicObservability& o, int i) {
  int best = 0;
  for (int k = 0; k < 6; ++k) {
    if (std::abs(o.basis_whitened(i, k)) > std::abs(o.basis_whitened(i, best))) best = k;
  }
  return best;
}

PartEstimate Part(const Vector6d& w, double information) {
  PartEstimate p;
  p.w = w;
  p.information_whitened = information * Matrix6d::Identity();
  return p;
}

Vector6d Axis(int i, double value) {
  Vector6d w = Vector6d::Zero();
  w(i) = value;
  return w;
}

TEST(HoldInsignificantTranslation, HoldsALeverArmShiftInsideItsOwnSigmas) {
  // x known 8x better than the prior (sigma 1/3 of the prior's), y 0.5x (sigma 0.82).
  Matrix6d H = 100.0 * Matrix6d::Identity();
  H(3, 3) = 8.0;
  H(4, 4) = 0.5;
  ExtrinsicObservability o = AnalyzeObservability(H, Vector6d::Ones(), 4.0);
  ASSERT_TRUE(o.axis_observed[3] && o.axis_observed[5]);
  Vector6d w = Axis(0, 0.01) + Axis(3, 0.9) + Axis(4, 0.9) + Axis(5, 0.5);
  // x moved 2.7 sigmas: kept; y 1.1 sigmas: held; rotation never touched, however small
  // its shift.
  EXPECT_EQ(HoldInsignificantTranslation(2.0, &o, &w), 1);
  EXPECT_DOUBLE_EQ(w(3), 0.9);
  EXPECT_DOUBLE_EQ(w(4), 0.0);
  EXPECT_DOUBLE_EQ(w(0), 0.01);
  EXPECT_DOUBLE_EQ(w(5), 0.5);
  EXPECT_TRUE(o.axis_observed[3]);  // kept: still calibrated
  // A smaller x shift (1.5 sigmas) goes back too, and is no longer reported as calibrated.
  w(3) = 0.5;
  EXPECT_EQ(HoldInsignificantTranslation(2.0, &o, &w), 1);
  EXPECT_DOUBLE_EQ(w(3), 0.0);
  EXPECT_FALSE(o.axis_observed[3]);
}

TEST(HoldInsignificantTranslation, NeverHoldsTheHeightApartFromThePitch) {
  // Height and pitch observed together: the data knows the sum of their whitened shifts
  // (what the homography of near ground sees) much better than either. A height shift of
  // one sigma of its own is the pair's answer, and holding it alone at the rough value
  // would leave the pitch's half of the pair where it was (the old rule held it: public_road
  // seed 3's IPM grid error went 0.044 -> 0.074 m).
  Matrix6d H = Matrix6d::Identity();
  H(1, 1) = H(5, 5) = H(1, 5) = H(5, 1) = 50.0;  // rank one in (pitch, z)
  ExtrinsicObservability o = AnalyzeObservability(H, Vector6d::Ones(), 4.0);
  Vector6d w = Axis(1, -0.3) + Axis(5, 0.3);
  const double z_sigma = 0.7;                // sqrt(C_55) with this H: about 0.71
  ASSERT_LT(std::abs(w(5)), 2.0 * z_sigma);  // what the old rule held
  EXPECT_EQ(HoldInsignificantTranslation(2.0, &o, &w), 0);
  EXPECT_DOUBLE_EQ(w(5), 0.3);
  EXPECT_DOUBLE_EQ(w(1), -0.3);
}

TEST(ConfirmedDirections, AgreeingPartsConfirmOnlyObservedDirections) {
  const ExtrinsicObservability o = RollYawZObserved();
  const Vector6d w_full = Axis(0, 0.3) + Axis(3, 1.0);  // roll, and the unobserved x
  const std::vector<std::array<PartEstimate, 2>> splits = {
      {Part(Axis(0, 0.25) + Axis(3, 0.9), 50.0), Part(Axis(0, 0.35) + Axis(3, 1.1), 50.0)}};
  const std::array<bool, 6> confirmed = ConfirmedDirections(o, w_full, splits, 4.0);
  EXPECT_TRUE(confirmed[DirectionOf(o, 0)]);   // roll: both halves move it alike
  EXPECT_FALSE(confirmed[DirectionOf(o, 3)]);  // x: never observed, never confirmed
  EXPECT_FALSE(confirmed[DirectionOf(o, 1)]);
}

TEST(ConfirmedDirections, ADisagreeingSplitSendsTheDirectionBack) {
  const ExtrinsicObservability o = RollYawZObserved();
  const Vector6d w_full = Axis(0, 0.3);
  // The halves agree; the markings and the lanes do not (one of them is biased).
  const std::array<PartEstimate, 2> halves = {Part(Axis(0, 0.3), 50.0), Part(Axis(0, 0.3), 50.0)};
  const std::array<PartEstimate, 2> opposite = {Part(Axis(0, 0.6), 50.0),
                                                Part(Axis(0, -0.1), 50.0)};
  EXPECT_FALSE(ConfirmedDirections(o, w_full, {halves, opposite}, 4.0)[DirectionOf(o, 0)]);
  // Same sign, but apart by more than the smaller of them: one element's pull, not the drive's.
  const std::array<PartEstimate, 2> apart = {Part(Axis(0, 0.5), 50.0), Part(Axis(0, 0.1), 50.0)};
  EXPECT_FALSE(ConfirmedDirections(o, w_full, {halves, apart}, 4.0)[DirectionOf(o, 0)]);
  EXPECT_TRUE(ConfirmedDirections(o, w_full, {halves}, 4.0)[DirectionOf(o, 0)]);
}

TEST(ConfirmedDirections, APartThatDoesNotObserveAbstains) {
  const ExtrinsicObservability o = RollYawZObserved();
  const Vector6d w_full = Axis(5, -0.4);  // z
  // Markings see z, lanes barely (information 1 < 4): that split cannot tell; the halves do.
  const std::array<PartEstimate, 2> halves = {Part(Axis(5, -0.45), 60.0),
                                              Part(Axis(5, -0.35), 60.0)};
  const std::array<PartEstimate, 2> kinds = {Part(Axis(5, -0.4), 60.0), Part(Axis(5, 0.0), 1.0)};
  EXPECT_TRUE(ConfirmedDirections(o, w_full, {halves, kinds}, 4.0)[DirectionOf(o, 5)]);
  // With no split able to tell, nothing is confirmed.
  EXPECT_FALSE(ConfirmedDirections(o, w_full, {kinds}, 4.0)[DirectionOf(o, 5)]);
  EXPECT_FALSE(ConfirmedDirections(o, w_full, {}, 4.0)[DirectionOf(o, 5)]);
}

TEST(ExtrinsicObservability, CountObservedRecountsRankAndAxes) {
  ExtrinsicObservability o = RollYawZObserved();
  ASSERT_EQ(o.rank, 3);
  ASSERT_TRUE(o.axis_observed[0]);
  o.observed[DirectionOf(o, 0)] = false;  // the cross-validation sent roll back
  o.CountObserved();
  EXPECT_EQ(o.rank, 2);
  EXPECT_FALSE(o.axis_observed[0]);
  EXPECT_TRUE(o.axis_observed[2]);
  EXPECT_TRUE(o.axis_observed[5]);
  EXPECT_EQ(ObservedAxesText(o.axis_observed), "yaw z");
  // The observed information no longer holds roll.
  EXPECT_NEAR(o.ObservedInformation()(0, 0), 0.0, 1e-9);
}

}  // namespace
}  // namespace window_solve
}  // namespace ipm_road_mapper
