// PartialViewCost: a partial view of a marking larger than the view associates by its
// measured sides, wherever along the cut directions its center lies.
#include <gtest/gtest.h>

#include "common/marking_test_utils.h"
#include "ipm_road_mapper/core/frontend/association.h"
#include "ipm_road_mapper/core/frontend/partial_view_association.h"

namespace ipm_road_mapper {
namespace {

// A 0.4 m x 14 m stop line across the road at x = 72, its near and far edges (sides 3, 1)
// measured, its ends (sides 0, 2) never seen.
MarkingElement StopLine() {
  MarkingElement e;
  e.corners_map = Rect(71.8, 72.2, -7.0, 7.0);
  e.side_measured = {false, true, false, true};
  e.center_cov_map = 0.01 * Eigen::Matrix2d::Identity();
  return e;
}

// Whether a cost passes the association's gate (3 sigma).
bool InGate(double cost) { return cost >= 0.0 && cost <= 9.0; }

// A view 6 m ahead showing 4.5 m of the line, cut by both image sides.
MarkingCandidate NearView(double dx, double y0, double y1) {
  MarkingCandidate c;
  c.corners_map = Rect(71.8 + dx, 72.2 + dx, y0, y1);
  c.side_measured = {false, true, false, true};
  c.complete = false;
  c.center_cov_map = 0.01 * Eigen::Matrix2d::Identity();
  return c;
}

TEST(PartialViewCost, ViewOfAPartAssociatesByItsSidesNotItsCenter) {
  const MarkingElement line = StopLine();
  AssociationOptions o;  // floor 0.2 m, gate 3 sigma
  const MarkingCandidate view = NearView(0.05, -4.1, 0.4);
  // Its center is 1.85 m from the line's along the line: outside the center gate.
  EXPECT_GT(MarkingAssociationCost(line, view, o), 9.0);
  const double cost = PartialViewCost(line, view, o);
  ASSERT_GE(cost, 0.0);
  EXPECT_LT(cost, 1.0);
  EXPECT_EQ(AssociateMarkings(std::vector<MarkingElement>{line}, {view}, o), std::vector<int>{0});
}

TEST(PartialViewCost, MeasuredSidesMustAgreeAndTheExtentsOverlap) {
  const MarkingElement line = StopLine();
  AssociationOptions o;
  // A parallel line 1.5 m farther: its measured sides are 1.5 m from the line's.
  EXPECT_FALSE(InGate(PartialViewCost(line, NearView(1.5, -4.1, 0.4), o)));
  // A view beyond the line's end along its length (the extents do not overlap).
  EXPECT_FALSE(InGate(PartialViewCost(line, NearView(0.0, 9.0, 13.0), o)));
  // Past an unmeasured end but overlapping: the extent grows, no cost for that.
  EXPECT_TRUE(InGate(PartialViewCost(line, NearView(0.0, 5.0, 9.0), o)));
}

TEST(PartialViewCost, MeasuredSideInsideALowerBoundDoesNotAssociate) {
  MarkingElement line = StopLine();
  AssociationOptions o;
  // A view that measured the line's end 3 m inside where earlier views already saw paint.
  MarkingCandidate view = NearView(0.0, -4.0, 4.0);
  view.side_measured = {false, true, true, true};
  EXPECT_FALSE(InGate(PartialViewCost(line, view, o)));
  // At the extent's end it does (and measures it).
  view.corners_map = Rect(71.8, 72.2, -4.0, 7.1);
  EXPECT_TRUE(InGate(PartialViewCost(line, view, o)));
}

}  // namespace
}  // namespace ipm_road_mapper
