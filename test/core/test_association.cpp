#include <gtest/gtest.h>

#include <cmath>

#include "ipm_road_mapper/core/frontend/association.h"

namespace ipm_road_mapper {
namespace {

std::array<Eigen::Vector3d, 4> Rectangle(double cx, double cy, double length, double width) {
  return {Eigen::Vector3d(cx - length / 2, cy - width / 2, 0),
          Eigen::Vector3d(cx + length / 2, cy - width / 2, 0),
          Eigen::Vector3d(cx + length / 2, cy + width / 2, 0),
          Eigen::Vector3d(cx - length / 2, cy + width / 2, 0)};
}

MarkingElement Marking(int class_id, double cx, double cy) {
  MarkingElement e;
  e.class_id = class_id;
  e.corners_map = Rectangle(cx, cy, 3.0, 1.0);
  return e;
}

// A straight lane along x at lateral offset y, from x0 to x1, control points every 3 m
// (phantom ends included).
LaneElement StraightLane(int class_id, double y, double x0, double x1) {
  LaneElement lane;
  lane.class_id = class_id;
  for (double x = x0 - 3.0; x <= x1 + 3.0 + 1e-9; x += 3.0) {
    lane.control_points_map.emplace_back(x, y, 0.0);
  }
  return lane;
}

LaneCandidate LinePoints(int class_id, double y, double x0, double x1) {
  LaneCandidate c;
  c.class_id = class_id;
  for (double x = x0; x <= x1 + 1e-9; x += 1.0) c.points_map.emplace_back(x, y, 0.0);
  return c;
}

TEST(BestCyclicShift, FindsTheRotationOfTheCorners) {
  const auto element = Rectangle(0, 0, 3, 1);
  for (int shift = 0; shift < 4; ++shift) {
    std::array<Eigen::Vector3d, 4> observed;
    for (int i = 0; i < 4; ++i) observed[(i + shift) % 4] = element[i] + Eigen::Vector3d(0.1, 0, 0);
    double mean = -1.0;
    EXPECT_EQ(BestCyclicShift(element, observed, &mean), shift);
    EXPECT_NEAR(mean, 0.1, 1e-12);
  }
}

TEST(AssociateMarkings, MatchesNearestOfSameClassWithinGate) {
  const std::vector<MarkingElement> elements = {Marking(10, 0, 0), Marking(10, 10, 0),
                                                Marking(20, 5, 0)};
  std::vector<MarkingCandidate> candidates(4);
  candidates[0] = {10, Rectangle(9.6, 0.2, 3, 1)};  // near element 1
  candidates[1] = {20, Rectangle(0.3, 0, 3, 1)};    // near element 0, but wrong class
  candidates[2] = {10, Rectangle(5.0, 0, 3, 1)};    // 5 m from both class-10 elements
  candidates[3] = {20, Rectangle(5.5, 0.5, 3, 1)};  // element 2
  AssociationOptions options;
  const auto match = AssociateMarkings(elements, candidates, options);
  EXPECT_EQ(match, (std::vector<int>{1, -1, -1, 2}));
}

TEST(AssociateMarkings, OneToOneWithinAFrame) {
  const std::vector<MarkingElement> elements = {Marking(10, 0, 0)};
  std::vector<MarkingCandidate> candidates = {{10, Rectangle(0.8, 0, 3, 1)},
                                              {10, Rectangle(0.2, 0, 3, 1)}};
  const auto match = AssociateMarkings(elements, candidates, AssociationOptions());
  EXPECT_EQ(match, (std::vector<int>{-1, 0}));  // the closer one wins, the other is new
}

TEST(AssociateMarkings, GateFollowsTheIpmCovariance) {
  // Far away, plain IPM errs along the viewing ray (here map x) by meters but across it by
  // centimeters: 2 m along the ray is the same marking, 1.2 m across it is another one.
  const std::vector<MarkingElement> elements = {Marking(10, 20, 0)};
  MarkingCandidate along{10, Rectangle(22.0, 0, 3, 1)};
  along.center_cov_map << 1.2 * 1.2, 0, 0, 0.04 * 0.04;
  MarkingCandidate across{10, Rectangle(20.0, 1.2, 3, 1)};
  across.center_cov_map = along.center_cov_map;
  const AssociationOptions options;
  EXPECT_EQ(AssociateMarkings(elements, {along}, options), (std::vector<int>{0}));
  EXPECT_EQ(AssociateMarkings(elements, {across}, options), (std::vector<int>{-1}));
  // Without the covariance, 2 m is beyond the gate of the isotropic floor.
  MarkingCandidate along_no_cov{10, Rectangle(22.0, 0, 3, 1)};
  EXPECT_EQ(AssociateMarkings(elements, {along_no_cov}, options), (std::vector<int>{-1}));
  EXPECT_GT(MarkingAssociationCost(elements[0], along_no_cov, options),
            MarkingAssociationCost(elements[0], along, options));
}

TEST(AssociateLanes, IgnoresPointsMarkedUnusable) {
  const std::vector<LaneElement> lanes = {StraightLane(2, 0.0, 0, 30)};
  // Near points on the line, far points 1.5 m off (an outer line seen far away).
  LaneCandidate candidate = LinePoints(2, 0.1, 5, 15);
  const std::size_t near = candidate.points_map.size();
  for (double x = 16; x <= 30; x += 1.0) candidate.points_map.emplace_back(x, 1.5, 0.0);
  EXPECT_LT(LaneAssociationCost(lanes[0], candidate, AssociationOptions()), 0.0);
  candidate.usable.assign(candidate.points_map.size(), false);
  for (std::size_t i = 0; i < near; ++i) candidate.usable[i] = true;
  const AssociationOptions options;
  EXPECT_NEAR(LaneAssociationCost(lanes[0], candidate, options), 0.1 / LaneFloorSigma(options),
              1e-6);
}

TEST(AssociateLanes, MatchesByLateralDistanceAndClass) {
  const std::vector<LaneElement> lanes = {StraightLane(2, 0.0, 0, 30), StraightLane(2, 3.5, 0, 30),
                                          StraightLane(1, -3.5, 0, 30)};
  const std::vector<LaneCandidate> candidates = {
      LinePoints(2, 3.3, 5, 25), LinePoints(2, 0.2, 5, 25), LinePoints(2, -3.5, 5, 25),
      LinePoints(2, 1.75, 5, 25)};  // halfway between two lanes: beyond the gates
  const auto match = AssociateLanes(lanes, candidates, AssociationOptions());
  EXPECT_EQ(match, (std::vector<int>{1, 0, -1, -1}));
}

TEST(AssociateLanes, LateralGateFollowsTheIpmCovariance) {
  // An outer line 5 m to the side seen at 10 m: plain IPM puts it 0.7 m off when the body
  // pitches, which is within its lateral sigma (0.25 m, plus the floor) but not within the
  // floor alone.
  const std::vector<LaneElement> lanes = {StraightLane(3, 5.0, 0, 30)};
  LaneCandidate candidate = LinePoints(3, 5.7, 9, 14);
  EXPECT_EQ(AssociateLanes(lanes, {candidate}, AssociationOptions())[0], -1);
  Eigen::Matrix2d cov;
  cov << 0.4 * 0.4, 0.4 * 0.25 * 0.9, 0.4 * 0.25 * 0.9, 0.25 * 0.25;
  candidate.cov_map.assign(candidate.points_map.size(), cov);
  EXPECT_EQ(AssociateLanes(lanes, {candidate}, AssociationOptions())[0], 0);
  // Beyond the hard cap in meters, no covariance helps.
  LaneCandidate far = LinePoints(3, 6.5, 9, 14);
  far.cov_map.assign(far.points_map.size(), 100.0 * cov);
  EXPECT_EQ(AssociateLanes(lanes, {far}, AssociationOptions())[0], -1);
}

TEST(AssociateLanes, GatesWidenWithTheOdometrysNoise) {
  // Odometry with 0.75 m of per-pose error: a frame's lane points 1.0 m off the lane are
  // the same line (the default odometry's gates, 0.16 m floor and 1.2 m cap, refuse them
  // in sigmas); a marking 1.5 m off likewise.
  const std::vector<LaneElement> lanes = {StraightLane(2, 0.0, 0, 30)};
  const LaneCandidate candidate = LinePoints(2, 1.0, 5, 25);
  AssociationOptions options;
  EXPECT_EQ(AssociateLanes(lanes, {candidate}, options)[0], -1);
  options.odometry_sigma_m = 0.75;
  EXPECT_EQ(AssociateLanes(lanes, {candidate}, options)[0], 0);
  EXPECT_NEAR(LaneFloorSigma(options), std::hypot(0.05, 0.75), 1e-12);
  // Beyond 3 of the widened sigmas: still refused.
  EXPECT_EQ(AssociateLanes(lanes, {LinePoints(2, 2.5, 5, 25)}, options)[0], -1);

  const std::vector<MarkingElement> markings = {Marking(10, 20.0, 0.0)};
  MarkingCandidate shifted{10, Rectangle(21.5, 0.0, 3.0, 1.0), Eigen::Matrix2d::Zero()};
  EXPECT_EQ(AssociateMarkings(markings, {shifted}, AssociationOptions())[0], -1);
  EXPECT_EQ(AssociateMarkings(markings, {shifted}, options)[0], 0);
}

TEST(AssociateLanes, PointsPastTheEndExtendTheLane) {
  const std::vector<LaneElement> lanes = {StraightLane(2, 0.0, 0, 30)};
  // Starts 2 m before the lane's end and runs 20 m past it, 0.1 m off the line.
  const auto match = AssociateLanes(lanes, {LinePoints(2, 0.1, 28, 50)}, AssociationOptions());
  EXPECT_EQ(match[0], 0);
  // Far past the end (beyond lane_max_end_gap_m): a new lane.
  const auto far = AssociateLanes(lanes, {LinePoints(2, 0.0, 60, 80)}, AssociationOptions());
  EXPECT_EQ(far[0], -1);
}

TEST(LaneEndLineLength, TheLastChordAtTheDefaultNoiseTheWholeReachWhenTheNoiseSetsTheGate) {
  AssociationOptions options;                  // 0.15 m of odometry noise
  EXPECT_LT(LaneEndLineLength(options), 3.0);  // under one chord: the end tangent, as before
  options.odometry_sigma_m = 0.5;              // 3 floor sigmas (1.51 m) exceed lane_gate_m (1.2 m)
  EXPECT_NEAR(LaneEndLineLength(options), options.lane_max_end_gap_m, 1e-12);
}

TEST(AssociateLanes, PastACurledEndTheNeighboursLineIsNotTheLanesAtHighNoise) {
  // Two dashed lines 3.5 m apart, both ending at x = 30 (a crossing where neither is
  // painted). Lane 0's last control point is 0.5 m off toward lane 1, as the newest, least
  // measured point is at 0.5 m of per-pose odometry noise: its last chord turns 9.5 deg
  // toward lane 1, and 12 m past the end that chord's line is on lane 1's line. Beyond the
  // crossing each line's observation continues its own lane.
  LaneElement curled = StraightLane(2, 3.5, 0, 30);
  const std::size_t n = curled.control_points_map.size();
  curled.control_points_map[n - 2].y() -= 0.5;
  curled.control_points_map[n - 1].y() -= 1.0;  // the phantom, 2 c_(n-2) - c_(n-3)
  const std::vector<LaneElement> lanes = {curled, StraightLane(2, 0.0, 0, 30)};
  AssociationOptions options;
  options.odometry_sigma_m = 0.5;
  const LaneCandidate lane1_beyond = LinePoints(2, 0.0, 40, 44);
  const LaneCandidate lane0_beyond = LinePoints(2, 3.5, 40, 44);
  EXPECT_LT(LaneAssociationCost(lanes[0], lane1_beyond, options), 0.0);
  const std::vector<int> match = AssociateLanes(lanes, {lane1_beyond, lane0_beyond}, options);
  EXPECT_EQ(match[0], 1);
  EXPECT_EQ(match[1], 0);
}

TEST(AssociateLanes, RejectsCrossingDirection) {
  const std::vector<LaneElement> lanes = {StraightLane(2, 0.0, 0, 30)};
  LaneCandidate crossing;
  crossing.class_id = 2;
  for (double y = -5; y <= 5; y += 1.0) crossing.points_map.emplace_back(15.0, y, 0.0);
  EXPECT_LT(LaneAssociationCost(lanes[0], crossing, AssociationOptions()), 0.0);
}

// A whole lane as the candidate (the merge of two lanes): each of its points is compared with
// the part of the lane near it, which decides as one piece around all of them would.
TEST(LaneAssociationCost, WholeLanesKilometersLong) {
  const AssociationOptions options;
  const LaneElement lane = StraightLane(2, 0.0, 0, 3000);
  EXPECT_GE(LaneAssociationCost(lane, LinePoints(2, 0.1, 1000, 2500), options), 0.0);
  EXPECT_LT(LaneAssociationCost(lane, LinePoints(2, 3.5, 0, 3000), options), 0.0);  // beside
  // Two thirds of it 30 m beside the lane (farther than any part near a point): no match.
  LaneCandidate bent = LinePoints(2, 0.1, 0, 1000);
  const LaneCandidate away = LinePoints(2, 30.0, 1000, 3000);
  bent.points_map.insert(bent.points_map.end(), away.points_map.begin(), away.points_map.end());
  EXPECT_LT(LaneAssociationCost(lane, bent, options), 0.0);
  // Past the lane's end within the end gap: still the lane.
  EXPECT_GE(LaneAssociationCost(lane, LinePoints(2, 0.1, 2000, 3010), options), 0.0);
}

TEST(AssociationOptions, RejectsUnknownAndBadKeys) {
  EXPECT_THROW(LoadAssociationOptions(OptionsReader(YAML::Load("lane_gate: 1.0"), "association")),
               OptionsError);
  EXPECT_THROW(
      LoadAssociationOptions(OptionsReader(YAML::Load("marking_gate_sigmas: -1"), "association")),
      OptionsError);
  const auto o =
      LoadAssociationOptions(OptionsReader(YAML::Load("marking_gate_sigmas: 2.5"), "association"));
  EXPECT_DOUBLE_EQ(o.marking_gate_sigmas, 2.5);
}

}  // namespace
}  // namespace ipm_road_mapper
