// Tests of the extent of a marking seen in partial views (marking_extent.h).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "common/marking_test_utils.h"
#include "ipm_road_mapper/core/mapper/marking_extent.h"

namespace ipm_road_mapper {
namespace {

// An element 4 m along x and 10 m along y whose sides 0 and 2 (y = -5, y = +5) were
// measured and whose sides 1 and 3 (x = 24, x = 20) were cut by the view.
MarkingElement PartialCrossing() {
  MarkingElement e;
  e.corners_map = Rect(20.0, 24.0, -5.0, 5.0);
  e.side_measured = {true, false, true, false};
  e.side_views = {1, 0, 1, 0};
  return e;
}

TEST(MarkingExtent, MeasuredSidesAreRunningMeansAndCutSidesDoNotShrink) {
  MarkingElement e = PartialCrossing();
  // A second view measuring sides 0 and 2 at y = -7 and y = 3, cut at x = 20 and 24 again.
  UpdateExtent(Rect(20.0, 24.0, -7.0, 3.0), {true, false, true, false}, false, &e);
  // The cut sides stay where they were (the view reaches no farther).
  EXPECT_NEAR(e.corners_map[0].x(), 20.0, 1e-9);
  EXPECT_NEAR(e.corners_map[1].x(), 24.0, 1e-9);
  // Measured sides 0 (y = -5 vs -7) and 2 (y = 5 vs 3): running means of two views.
  EXPECT_NEAR(e.corners_map[0].y(), -6.0, 1e-9);
  EXPECT_NEAR(e.corners_map[2].y(), 4.0, 1e-9);
  EXPECT_EQ(e.side_views[0], 2u);
}

TEST(MarkingExtent, UnmeasuredSideGrowsToTheFarthestViewAndTheFirstMeasurementSetsIt) {
  MarkingElement e;
  e.corners_map = Rect(0.0, 10.0, 0.0, 4.0);
  e.side_measured = {true, false, true, true};  // side 1 (x = 10) not yet seen
  e.side_views = {1, 0, 1, 1};
  UpdateExtent(Rect(0.0, 14.0, 0.0, 4.0), {true, false, true, true}, false, &e);
  EXPECT_NEAR(e.corners_map[1].x(), 14.0, 1e-9);  // grew with the cut view
  UpdateExtent(Rect(0.0, 12.0, 0.0, 4.0), {true, false, true, true}, false, &e);
  EXPECT_NEAR(e.corners_map[1].x(), 14.0, 1e-9);  // a shorter cut view never shrinks it
  UpdateExtent(Rect(0.0, 16.0, 0.0, 4.0), {true, true, true, true}, false, &e);
  EXPECT_NEAR(e.corners_map[1].x(), 16.0, 1e-9);  // the first measurement replaces the bound
  EXPECT_NEAR(e.corners_map[2].x(), 16.0, 1e-9);
  EXPECT_TRUE(e.side_measured[1]);
  EXPECT_TRUE(e.Complete());
}

TEST(MarkingExtent, OwnedElementMovesOnlyUnmeasuredSides) {
  MarkingElement e;
  e.corners_map = Rect(0.0, 10.0, 0.0, 4.0);
  e.side_measured = {true, false, true, true};
  e.side_views = {1, 0, 1, 1};
  UpdateExtent(Rect(1.0, 13.0, 0.5, 4.5), {true, false, true, true}, true, &e);
  EXPECT_NEAR(e.corners_map[0].y(), 0.0, 1e-9);  // the back end owns measured sides
  EXPECT_NEAR(e.corners_map[0].x(), 0.0, 1e-9);
  EXPECT_NEAR(e.corners_map[1].x(), 13.0, 1e-9);  // the open end still grows
}

TEST(MarkingExtent, SideAlignedShiftPairsSidesOfASmallerView) {
  const std::array<Eigen::Vector3d, 4> element = Rect(0.0, 20.0, 0.0, 4.0);
  // The view's corners start at its top-right corner (shift 2 of the element's order).
  const std::array<Eigen::Vector3d, 4> view = {Eigen::Vector3d(6, 4, 0), Eigen::Vector3d(2, 4, 0),
                                               Eigen::Vector3d(2, 0, 0), Eigen::Vector3d(6, 0, 0)};
  EXPECT_EQ(SideAlignedShift(element, view), 2);
  EXPECT_EQ(SideAlignedShift(element, element), 0);
}

TEST(MarkingExtent, RectifiedPartialExtentKeepsItsShapeAndItsUnmeasuredSides) {
  // A solve slid the cut corner 2 of a 4 m x 10 m crossing (between the cut side 1, x = 24,
  // and the measured side 2, y = 5) 6 m inwards along side 2's line, moved the measured sides
  // by 0.1 m and raised corner 2 by 0.3 m.
  const MarkingElement before = PartialCrossing();
  std::array<Eigen::Vector3d, 4> refined = Rect(20.0, 24.0, -4.9, 5.1);
  refined[2].x() -= 6.0;
  refined[2].z() = 0.3;
  const std::array<Eigen::Vector3d, 4> r =
      RectifyPartialExtent(before.corners_map, refined, before.side_measured);
  // Measured sides where the solve put them, the cut ones where the extent had them.
  const std::array<Eigen::Vector3d, 4> expected = Rect(20.0, 24.0, -4.9, 5.1);
  for (int c = 0; c < 4; ++c) {
    EXPECT_NEAR(r[c].x(), expected[c].x(), 1e-9) << "corner " << c;
    EXPECT_NEAR(r[c].y(), expected[c].y(), 1e-9) << "corner " << c;
  }
  EXPECT_NEAR(r[2].z(), 0.3, 1e-12);  // heights are the solve's
}

TEST(MarkingExtent, RectifiedPartialExtentTakesTheMeasuredSidesOrientation) {
  // The solve turned the measured sides by 2 deg about the element's center: so does the
  // rectangle, with the cut sides still at their offsets along the turned normals.
  const MarkingElement before = PartialCrossing();
  const double a = 2.0 * M_PI / 180.0;
  const Eigen::Matrix3d R = Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  std::array<Eigen::Vector3d, 4> refined = before.corners_map;
  const Eigen::Vector3d center(22.0, 0.0, 0.0);
  for (Eigen::Vector3d& c : refined) c = center + R * (c - center);
  const std::array<Eigen::Vector3d, 4> r =
      RectifyPartialExtent(before.corners_map, refined, before.side_measured);
  const Eigen::Vector2d side0 = (r[1] - r[0]).head<2>();
  EXPECT_NEAR(std::atan2(side0.y(), side0.x()), a, 1e-9);
  EXPECT_NEAR(side0.dot((r[2] - r[1]).head<2>()), 0.0, 1e-9);
}

}  // namespace
}  // namespace ipm_road_mapper
