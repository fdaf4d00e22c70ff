// AssociateMarkingsRegistered and LaneOffsetAcross: a frame's markings shifted together by
// its pose error are associated in the frame its lanes register, where the odometry's noise
// sets the gates.
#include <gtest/gtest.h>

#include <cmath>

#include "ipm_road_mapper/core/frontend/frame_registration.h"

namespace ipm_road_mapper {
namespace {

constexpr int kStripe = 20;

std::array<Eigen::Vector3d, 4> Rectangle(double cx, double cy, double length, double width) {
  return {Eigen::Vector3d(cx - length / 2, cy - width / 2, 0),
          Eigen::Vector3d(cx + length / 2, cy - width / 2, 0),
          Eigen::Vector3d(cx + length / 2, cy + width / 2, 0),
          Eigen::Vector3d(cx - length / 2, cy + width / 2, 0)};
}

// A crossing on a road along x: stripes 3 m long (along x), 0.5 m wide, 1 m apart across.
std::vector<MarkingElement> Crossing(int stripes) {
  std::vector<MarkingElement> elements;
  for (int i = 0; i < stripes; ++i) {
    MarkingElement e;
    e.class_id = kStripe;
    e.corners_map = Rectangle(20.0, i * 1.0, 3.0, 0.5);
    elements.push_back(e);
  }
  return elements;
}

std::vector<const MarkingElement*> Pointers(const std::vector<MarkingElement>& elements) {
  std::vector<const MarkingElement*> p;
  for (const MarkingElement& e : elements) p.push_back(&e);
  return p;
}

// The crossing's stripes seen from a frame whose pose is `across` m off to the right of the
// road (the observations land `across` m to the left of their markings), each with a small
// own error (alternating sign).
std::vector<MarkingCandidate> SeenFromAFrameOff(int stripes, double across, double own) {
  std::vector<MarkingCandidate> candidates;
  for (int i = 0; i < stripes; ++i) {
    const double e = (i % 2 == 0 ? 1.0 : -1.0) * own;
    candidates.push_back(
        {kStripe, Rectangle(20.0 + e, i * 1.0 + across + e, 3.0, 0.5), Eigen::Matrix2d::Zero()});
  }
  return candidates;
}

AssociationOptions NoisyOdometry() {
  AssociationOptions options;
  options.odometry_sigma_m = 0.75;  // told for 0.5 m of per-pose noise
  return options;
}

TEST(NoiseSetsTheGates, FromAbout0_4MOfOdometryNoise) {
  AssociationOptions options;  // 0.15 m
  EXPECT_FALSE(NoiseSetsTheGates(options));
  options.odometry_sigma_m = 0.3;
  EXPECT_FALSE(NoiseSetsTheGates(options));
  options.odometry_sigma_m = 0.4;
  EXPECT_TRUE(NoiseSetsTheGates(options));
  EXPECT_TRUE(NoiseSetsTheGates(NoisyOdometry()));
}

TEST(AssociateMarkingsRegistered, ACrossingSeenFromAFrameOffGoesStripeByStripe) {
  // The frame is 0.6 m off across the road: each seen stripe is nearer its neighbour's
  // element (0.4 m) than its own (0.6 m), and the 2.25 m gates admit both.
  const AssociationOptions options = NoisyOdometry();
  const std::vector<MarkingElement> crossing = Crossing(7);
  const auto elements = Pointers(crossing);
  const std::vector<MarkingCandidate> candidates = SeenFromAFrameOff(7, 0.6, 0.05);
  const std::vector<int> plain = AssociateMarkings(elements, candidates, options);
  int own = 0;
  for (int i = 0; i < 7; ++i) own += plain[i] == i ? 1 : 0;
  EXPECT_LT(own, 4);  // one by one, most stripes take their neighbour's element
  // The lanes measure the frame 0.55 m off (to the right of the heading: -0.55 to the left).
  const Eigen::Vector2d heading = Eigen::Vector2d::UnitX();
  const std::vector<int> registered =
      AssociateMarkingsRegistered(elements, candidates, options, heading, -0.55);
  for (int i = 0; i < 7; ++i) EXPECT_EQ(registered[i], i) << "stripe " << i;
  // Driving the other way, the same offset is to the left of the heading.
  const std::vector<int> reversed =
      AssociateMarkingsRegistered(elements, candidates, options, -heading, 0.55);
  EXPECT_EQ(reversed, registered);
}

TEST(AssociateMarkingsRegistered, OtherwiseItIsThePlainAssociation) {
  const std::vector<MarkingElement> crossing = Crossing(7);
  const auto elements = Pointers(crossing);
  const std::vector<MarkingCandidate> candidates = SeenFromAFrameOff(7, 0.6, 0.05);
  const Eigen::Vector2d heading = Eigen::Vector2d::UnitX();
  const AssociationOptions noisy = NoisyOdometry();
  const std::vector<int> plain = AssociateMarkings(elements, candidates, noisy);
  // No lane offset, or not a finite one.
  EXPECT_EQ(AssociateMarkingsRegistered(elements, candidates, noisy, heading, std::nullopt), plain);
  EXPECT_EQ(AssociateMarkingsRegistered(elements, candidates, noisy, heading, std::nan("")), plain);
  // The default odometry does not set the gates: no registration.
  const AssociationOptions precise;
  EXPECT_EQ(AssociateMarkingsRegistered(elements, candidates, precise, heading, -0.55),
            AssociateMarkings(elements, candidates, precise));
}

// A straight lane along x at y, control points every 3 m over [x0, x1], phantoms included.
LaneElement StraightLane(double y, double x0, double x1) {
  LaneElement lane;
  lane.class_id = 2;
  for (double x = x0 - 3.0; x <= x1 + 3.0 + 1e-9; x += 3.0) {
    lane.control_points_map.emplace_back(x, y, 0.0);
  }
  return lane;
}

LaneCandidate LinePoints(double y, double x0, double x1) {
  LaneCandidate c;
  c.class_id = 2;
  for (double x = x0; x <= x1 + 1e-9; x += 1.0) c.points_map.emplace_back(x, y, 0.0);
  return c;
}

TEST(LaneOffsetAcross, TheSignedMedianOffsetOfThePointsBesideTheLane) {
  const LaneElement lane = StraightLane(3.5, 0.0, 30.0);
  const Eigen::Vector2d left = Eigen::Vector2d::UnitY();
  // Seen 0.4 m to the right of the lane: move 0.4 m to the left to lie on it.
  EXPECT_NEAR(LaneOffsetAcross(lane, LinePoints(3.1, 5.0, 20.0), left), 0.4, 1e-6);
  EXPECT_NEAR(LaneOffsetAcross(lane, LinePoints(3.1, 5.0, 20.0), -left), -0.4, 1e-6);
  // One point far off does not move the median.
  LaneCandidate outlier = LinePoints(3.1, 5.0, 20.0);
  outlier.points_map[3].y() = 10.0;
  EXPECT_NEAR(LaneOffsetAcross(lane, outlier, left), 0.4, 1e-6);
  // Points past the lane's end say nothing across it.
  EXPECT_TRUE(std::isnan(LaneOffsetAcross(lane, LinePoints(3.1, 35.0, 42.0), left)));
  // Unusable points are not counted.
  LaneCandidate unusable = LinePoints(3.1, 5.0, 20.0);
  unusable.usable.assign(unusable.points_map.size(), false);
  EXPECT_TRUE(std::isnan(LaneOffsetAcross(lane, unusable, left)));
}

}  // namespace
}  // namespace ipm_road_mapper
