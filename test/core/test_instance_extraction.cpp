// Marking extraction (instance_extraction.h): corners in canonical order against the truth,
// partial views and cut sides, the drops (tiny, unknown class, range, degenerate), the
// rectangle along the road over all of an instance's glyphs, random shapes. Lanes:
// test_lane_extraction; bad and huge masks, limits, timing: test_extraction_bounds.
#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "../../src/core/frontend/instance_extraction_runs.h"  // BoundingRectangle
#include "common/extraction_scene.h"
#include "ipm_road_mapper/core/frontend/instance_extraction.h"

namespace ipm_road_mapper {
namespace {

TEST_F(InstanceExtractionTest, MarkingCornersMatchTruthInCanonicalOrder) {
  const Eigen::Vector2d center(10.0, 0.0);
  const FrameObservations obs = ExtractRectangle(center, 2.0, 0.5, 20 * kDeg, kArrow + 3);
  ASSERT_EQ(obs.markings.size(), 1u);
  EXPECT_TRUE(obs.lanes.empty());
  EXPECT_EQ(obs.counters.instances_seen, 1u);
  // Re-oriented along the road's direction (the mapper's part; 20 deg here).
  MarkingObservation m = obs.markings[0];
  ASSERT_TRUE(SetMarkingRectangle(ipm_, error_model_,
                                  Eigen::Vector2d(std::cos(20 * kDeg), std::sin(20 * kDeg)), &m));
  EXPECT_EQ(m.class_id, 10);
  EXPECT_EQ(m.instance_value, kArrow + 3);
  EXPECT_GT(m.pixel_count, 500);

  const double error = MaxCornerError(m, GroundRectangle(center, 2.0, 0.5, 20 * kDeg));
  std::cout << "[ info ] 2x0.5 m rectangle at 10 m, yaw 20 deg: max corner error " << error
            << " m\n";
  EXPECT_LT(error, 0.05);

  // Canonical order: the first corner is the nearest, the polygon is counter-clockwise.
  double twice_area = 0.0;
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector3d& a = m.corners_base[i];
    const Eigen::Vector3d& b = m.corners_base[(i + 1) % 4];
    twice_area += a.x() * b.y() - b.x() * a.y();
    EXPECT_EQ(a.z(), 0.0);
    EXPECT_LE(m.corners_base[0].head<2>().norm(), a.head<2>().norm());
  }
  EXPECT_NEAR(twice_area, 2.0 * 2.0 * 0.5, 0.1);

  // The pixel measurements are the projections of the ground corners.
  for (int i = 0; i < 4; ++i) {
    Eigen::Vector2d uv;
    ASSERT_TRUE(ipm_.BaseToPixel(m.corners_base[i], &uv));
    EXPECT_LT((uv - m.corners_uv[i]).norm(), 1e-9);
    EXPECT_TRUE(ipm_.camera().InImage(m.corners_uv[i]));
  }
}

TEST_F(InstanceExtractionTest, MarkingCornersAccurateOverPosesAndYaws) {
  double worst = 0.0;
  for (const Eigen::Vector2d& center :
       {Eigen::Vector2d(7.0, -1.5), Eigen::Vector2d(10.0, 0.4), Eigen::Vector2d(14.0, 2.0)}) {
    for (double yaw_deg : {0.0, 10.0, 20.0, 45.0, 70.0, 90.0, -30.0}) {
      FrameObservations obs = ExtractRectangle(center, 2.0, 0.5, yaw_deg * kDeg, kArrow);
      ASSERT_EQ(obs.markings.size(), 1u) << center.transpose() << " yaw " << yaw_deg;
      const Eigen::Vector2d axis(std::cos(yaw_deg * kDeg), std::sin(yaw_deg * kDeg));
      ASSERT_TRUE(SetMarkingRectangle(ipm_, error_model_, axis, &obs.markings[0]));
      const double error =
          MaxCornerError(obs.markings[0], GroundRectangle(center, 2.0, 0.5, yaw_deg * kDeg));
      EXPECT_LT(error, 0.06) << center.transpose() << " yaw " << yaw_deg;
      worst = std::max(worst, error);
    }
  }
  std::cout << "[ info ] worst corner error over 21 rectangles (7-14 m): " << worst << " m\n";
}

TEST_F(InstanceExtractionTest, MarkingCutByTheBottomBorderIsAPartialView) {
  // The bottom image row sees the ground about 3.3 m ahead: this rectangle (2.0-4.0 m) is
  // cut there. Its near side is where the view ends; the far side and the lateral sides are
  // the marking's own, and so are the two far corners.
  const FrameObservations obs = ExtractRectangle({3.0, 0.0}, 2.0, 1.0, 0.0, kArrow);
  ASSERT_EQ(obs.markings.size(), 1u);
  EXPECT_EQ(obs.counters.dropped_border, 0u);
  EXPECT_EQ(obs.counters.partial_markings, 1u);
  const MarkingObservation& m = obs.markings[0];
  EXPECT_FALSE(m.Complete());
  // Exactly the side whose corners are nearest (x smallest) is cut.
  int cut_sides = 0;
  for (int s = 0; s < 4; ++s) {
    const double near_x = std::max(m.corners_base[s].x(), m.corners_base[(s + 1) % 4].x());
    if (!m.side_measured[s]) {
      ++cut_sides;
      EXPECT_LT(near_x, 3.5) << "side " << s;
      EXPECT_TRUE(m.side_uv[s].empty());
    } else {
      EXPECT_GE(m.side_uv[s].size(), 1u);  // boundary pixels for the edge residual
    }
  }
  EXPECT_EQ(cut_sides, 1);
  // The measured corners are the far ones, the marking's (4.0, -0.5) and (4.0, 0.5).
  int measured_corners = 0;
  for (int i = 0; i < 4; ++i) {
    if (!m.CornerMeasured(i)) continue;
    ++measured_corners;
    EXPECT_NEAR(m.corners_base[i].x(), 4.0, 0.05);
    EXPECT_NEAR(std::abs(m.corners_base[i].y()), 0.5, 0.05);
  }
  EXPECT_EQ(measured_corners, 2);
}

TEST_F(InstanceExtractionTest, WholeMarkingHasEverySideMeasured) {
  const FrameObservations obs = ExtractRectangle({10.0, 0.5}, 2.0, 0.5, 0.0, kArrow);
  ASSERT_EQ(obs.markings.size(), 1u);
  EXPECT_TRUE(obs.markings[0].Complete());
  EXPECT_EQ(obs.counters.partial_markings, 0u);
}

TEST_F(InstanceExtractionTest, MarkingCutByAnotherInstanceHasThatSideCut) {
  // A stripe 8-12 m ahead whose far part is hidden by an occluder instance painted over it
  // (an unknown class: a vehicle): its far side is where the view ends.
  cv::Mat mask = EmptyMask();
  RenderGroundRectangle(ipm_, {10.0, 0.0}, 4.0, 1.0, 0.0, kArrow + 1, &mask);
  RenderGroundRectangle(ipm_, {13.0, 0.0}, 3.0, 3.0, 0.0, kUnknownClass + 1, &mask);
  const FrameObservations obs = Extract(mask);
  ASSERT_EQ(obs.markings.size(), 1u);
  const MarkingObservation& m = obs.markings[0];
  // One side cut, the far one (its corners beyond 11 m); the near corners measured.
  for (int s = 0; s < 4; ++s) {
    const double min_x = std::min(m.corners_base[s].x(), m.corners_base[(s + 1) % 4].x());
    EXPECT_EQ(m.side_measured[s], min_x < 11.0) << "side " << s;
  }
  for (int i = 0; i < 4; ++i) EXPECT_EQ(m.CornerMeasured(i), m.corners_base[i].x() < 11.0);
}

TEST_F(InstanceExtractionTest, TinyMarkingIsDropped) {
  const FrameObservations obs = ExtractRectangle({20.0, 0.0}, 0.3, 0.2, 0.0, kArrow);
  EXPECT_TRUE(obs.markings.empty());
  EXPECT_EQ(obs.counters.dropped_tiny, 1u);
}

TEST_F(InstanceExtractionTest, UnknownClassIsDropped) {
  const FrameObservations obs = ExtractRectangle({10.0, 0.0}, 2.0, 0.5, 0.0, kUnknownClass + 1);
  EXPECT_TRUE(obs.markings.empty());
  EXPECT_TRUE(obs.lanes.empty());
  EXPECT_EQ(obs.counters.dropped_unknown_class, 1u);
}

TEST_F(InstanceExtractionTest, FarMarkingIsDroppedByRange) {
  options_.max_marking_range_m = 25.0;
  options_.min_marking_pixels = 10;  // at 45 m the marking covers only a few rows
  const FrameObservations far = ExtractRectangle({45.0, 0.0}, 3.0, 3.0, 0.0, kArrow);
  EXPECT_TRUE(far.markings.empty());
  EXPECT_EQ(far.counters.dropped_range, 1u);
  // The same marking within range is kept (the drop is the range, not its size).
  options_.max_marking_range_m = 50.0;
  EXPECT_EQ(ExtractRectangle({45.0, 0.0}, 3.0, 3.0, 0.0, kArrow).markings.size(), 1u);
}

TEST_F(InstanceExtractionTest, FarWholeViewIsKeptAsAFarViewFarPartialOneIsNot) {
  options_.max_marking_range_m = 25.0;
  options_.far_marking_range_m = 50.0;
  options_.min_marking_pixels = 10;
  // Beyond the near range, within the far one, whole: a far view.
  const FrameObservations far = ExtractRectangle({45.0, 0.0}, 3.0, 3.0, 0.0, kArrow);
  ASSERT_EQ(far.markings.size(), 1u);
  EXPECT_TRUE(far.markings[0].far);
  EXPECT_TRUE(far.markings[0].Complete());
  // Within the near range: no far view.
  const FrameObservations near = ExtractRectangle({15.0, 0.0}, 3.0, 3.0, 0.0, kArrow);
  ASSERT_EQ(near.markings.size(), 1u);
  EXPECT_FALSE(near.markings[0].far);
  // Cut by the IPM's 50 m range: a far partial view, dropped by range.
  const FrameObservations cut = ExtractRectangle({49.0, 0.0}, 4.0, 3.0, 0.0, kArrow);
  EXPECT_TRUE(cut.markings.empty());
  EXPECT_EQ(cut.counters.dropped_range, 1u);
  // Off (0): beyond the near range is dropped, as before far views.
  options_.far_marking_range_m = 0.0;
  EXPECT_TRUE(ExtractRectangle({45.0, 0.0}, 3.0, 3.0, 0.0, kArrow).markings.empty());
}

TEST_F(InstanceExtractionTest, MarkingCutByIpmRangeKeepsThePartInRange) {
  // From 45 to 55 m: the part beyond the IPM's 50 m does not map. The part in range is kept
  // (clipped at the range), its far side cut there, its near side and corners measured.
  options_.max_marking_range_m = 60.0;
  options_.min_marking_pixels = 10;
  const FrameObservations obs = ExtractRectangle({50.0, 0.0}, 10.0, 4.0, 0.0, kArrow);
  ASSERT_EQ(obs.markings.size(), 1u);
  EXPECT_EQ(obs.counters.dropped_range, 0u);
  const MarkingObservation& m = obs.markings[0];
  for (int s = 0; s < 4; ++s) {  // the far side (at the range) is cut, the near one is not
    const double min_x = std::min(m.corners_base[s].x(), m.corners_base[(s + 1) % 4].x());
    if (min_x > 48.0) {
      EXPECT_FALSE(m.side_measured[s]) << "side " << s;
    }
    if (std::max(m.corners_base[s].x(), m.corners_base[(s + 1) % 4].x()) < 46.0) {
      EXPECT_TRUE(m.side_measured[s]) << "side " << s;
    }
  }
  for (const Eigen::Vector2d& p : m.outline_base) EXPECT_LE(p.norm(), 50.0 + 1e-6);
  // Near edge at 45 m, where one image row spans about 0.7 m of road.
  EXPECT_NEAR(std::min(m.corners_base[0].x(), m.corners_base[1].x()), 45.0, 1.0);
}

TEST_F(InstanceExtractionTest, ThinRectangleIsDegenerate) {
  options_.min_rectangle_side_m = 0.6;
  const FrameObservations obs = ExtractRectangle({10.0, 0.0}, 2.0, 0.5, 0.0, kStopLine);
  EXPECT_TRUE(obs.markings.empty());
  EXPECT_EQ(obs.counters.dropped_degenerate, 1u);
}

TEST(BoundingRectangle, SpansTheOutlineAlongTheGivenAxis) {
  // A straight arrow 5 m long (shaft 0.3 m wide, head 1.2 m wide) turned by 30 deg: along
  // its axis, its bounding rectangle is 5 x 1.2 m. (The minimum-area rectangle of this hull
  // lies along a slanted edge of the head, 0.3-0.4 m off at the corners.)
  const std::vector<Eigen::Vector2d> arrow_local = {
      {0.0, -0.15}, {3.5, -0.15}, {3.5, -0.6}, {5.0, 0.0}, {3.5, 0.6}, {3.5, 0.15}, {0.0, 0.15}};
  const double yaw = 30.0 * M_PI / 180.0;
  const Eigen::Rotation2Dd R(yaw);
  const Eigen::Vector2d offset(12.0, -2.0);
  std::vector<Eigen::Vector2d> hull;  // the convex hull, as the outline is
  for (int i : {0, 1, 2, 3, 4, 6}) hull.push_back(offset + R * arrow_local[i]);
  const auto rect =
      extraction::BoundingRectangle(hull, 2.0 * Eigen::Vector2d(std::cos(yaw), std::sin(yaw)));
  const std::array<Eigen::Vector2d, 4> expected = {
      offset + R * Eigen::Vector2d(0.0, -0.6), offset + R * Eigen::Vector2d(5.0, -0.6),
      offset + R * Eigen::Vector2d(5.0, 0.6), offset + R * Eigen::Vector2d(0.0, 0.6)};
  for (int i = 0; i < 4; ++i) EXPECT_LT((rect[i] - expected[i]).norm(), 1e-9) << i;
  // Along x instead: the axis-aligned box of the hull.
  const auto box = extraction::BoundingRectangle(hull, Eigen::Vector2d::UnitX());
  double x_min = 1e9, x_max = -1e9;
  for (const auto& p : hull) x_min = std::min(x_min, p.x()), x_max = std::max(x_max, p.x());
  EXPECT_NEAR(box[0].x(), x_min, 1e-9);
  EXPECT_NEAR(box[1].x(), x_max, 1e-9);
}

TEST_F(InstanceExtractionTest, SetMarkingRectangleReorientsAlongTheRoad) {
  // A 3 x 0.8 m marking turned by 10 deg (a curve ahead): extracted along base_link's x it
  // is the larger axis-aligned box; re-oriented along the road it is the marking itself.
  cv::Mat mask = EmptyMask();
  const double yaw = 10.0 * M_PI / 180.0;
  RenderGroundRectangle(ipm_, {12.0, 1.2}, 3.0, 0.8, yaw, kArrow, &mask);
  FrameObservations obs = Extract(mask);
  ASSERT_EQ(obs.markings.size(), 1u);
  const auto truth = GroundRectangle({12.0, 1.2}, 3.0, 0.8, yaw);
  EXPECT_GT(MaxCornerError(obs.markings[0], truth), 0.1);
  ASSERT_TRUE(SetMarkingRectangle(ipm_, IpmErrorModel(),
                                  Eigen::Vector2d(std::cos(yaw), std::sin(yaw)), &obs.markings[0]));
  EXPECT_LT(MaxCornerError(obs.markings[0], truth), 0.06);  // a pixel is ~0.1 m deep at 12 m
  // The pixel corners follow.
  for (int i = 0; i < 4; ++i) {
    Eigen::Vector2d uv;
    ASSERT_TRUE(ipm_.BaseToPixel(obs.markings[0].corners_base[i], &uv));
    EXPECT_LT((uv - obs.markings[0].corners_uv[i]).norm(), 1e-9);
  }
}

TEST_F(InstanceExtractionTest, MarkingRectangleSpansAllItsGlyphs) {
  // A speed limit "60": two glyphs of one instance, side by side across the road. The
  // marking is their common bounding rectangle (off the x axis, so that one corner is the
  // nearest), not the larger glyph (which would make the
  // observed rectangle jump between glyphs from frame to frame).
  cv::Mat mask = EmptyMask();
  RenderGroundRectangle(ipm_, {10.0, 0.15}, 1.4, 0.6, 0.0, kArrow, &mask);
  RenderGroundRectangle(ipm_, {10.0, 1.05}, 1.4, 0.6, 0.0, kArrow, &mask);
  const FrameObservations obs = Extract(mask);
  ASSERT_EQ(obs.markings.size(), 1u);
  EXPECT_LT(MaxCornerError(obs.markings[0], GroundRectangle({10.0, 0.6}, 1.4, 1.5, 0.0)), 0.05);
}

TEST_F(InstanceExtractionTest, MarkingLeavesOutSpecksOfItsInstance) {
  cv::Mat mask = EmptyMask();
  // Off the x axis: a rectangle centered on it has two corners equally near the origin.
  RenderGroundRectangle(ipm_, {10.0, 0.4}, 2.0, 0.5, 0.0, kArrow, &mask);
  // A stray blob of the same instance far to the side.
  mask(cv::Rect(1000, 500, 3, 3)).setTo(kArrow);
  const FrameObservations obs = Extract(mask);
  ASSERT_EQ(obs.markings.size(), 1u);
  EXPECT_LT(MaxCornerError(obs.markings[0], GroundRectangle({10.0, 0.4}, 2.0, 0.5, 0.0)), 0.05);
  EXPECT_EQ(obs.markings[0].pixel_count, cv::countNonZero(mask));
}

// True when the ground point lies inside the (counter-clockwise) rectangle, up to tol_m.
bool InsideRectangle(const std::array<Eigen::Vector3d, 4>& corners, const Eigen::Vector3d& p,
                     double tol_m) {
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector2d edge = (corners[(i + 1) % 4] - corners[i]).head<2>().normalized();
    const Eigen::Vector2d to_p = (p - corners[i]).head<2>();
    if (edge.x() * to_p.y() - edge.y() * to_p.x() < -tol_m) return false;
  }
  return true;
}

TEST_F(InstanceExtractionTest, RandomShapesGiveValidRectanglesContainingTheirPixels) {
  // Triangles, ellipses and 1-3 px lines down to single pixels (every outline path: hull,
  // squeezed offset edges, collinear fallback). Each rectangle must be finite, canonical,
  // and contain the ground point of every pixel center of its instance.
  options_.min_marking_pixels = 1;
  options_.min_rectangle_side_m = 0.0;
  options_.max_marking_range_m = 50.0;
  cv::RNG rng(7);
  int extracted = 0;
  for (int trial = 0; trial < 300; ++trial) {
    cv::Mat mask = EmptyMask();
    const cv::Point origin(rng.uniform(20, 1060), rng.uniform(380, 560));
    const cv::Scalar value(kArrow + trial % 100);
    switch (trial % 3) {
      case 0: {
        std::vector<cv::Point> triangle;
        for (int k = 0; k < 3; ++k) {
          triangle.push_back(origin + cv::Point(rng.uniform(0, 200), rng.uniform(0, 140)));
        }
        cv::fillConvexPoly(mask, triangle, value);
        break;
      }
      case 1:
        cv::ellipse(mask, origin + cv::Point(100, 70),
                    cv::Size(rng.uniform(0, 90), rng.uniform(0, 60)), rng.uniform(0.0, 180.0), 0.0,
                    360.0, value, cv::FILLED);
        break;
      default:
        cv::line(mask, origin, origin + cv::Point(rng.uniform(-80, 80), rng.uniform(0, 120)), value,
                 rng.uniform(1, 4));
    }
    // Every shape lies in this window around its origin.
    const cv::Rect window =
        cv::Rect(origin.x - 100, origin.y - 30, 320, 200) & cv::Rect(0, 0, kTestWidth, kTestHeight);
    const FrameObservations obs = Extract(mask);
    ASSERT_EQ(obs.counters.instances_seen, 1u) << "trial " << trial;
    ASSERT_EQ(cv::countNonZero(mask(window)), cv::countNonZero(mask)) << "trial " << trial;
    if (obs.markings.empty()) continue;
    ++extracted;
    const MarkingObservation& m = obs.markings[0];
    double twice_area = 0.0;
    for (int i = 0; i < 4; ++i) {
      ASSERT_TRUE(m.corners_base[i].allFinite() && m.corners_uv[i].allFinite()) << trial;
      const Eigen::Vector3d& a = m.corners_base[i];
      const Eigen::Vector3d& b = m.corners_base[(i + 1) % 4];
      twice_area += a.x() * b.y() - b.x() * a.y();
      EXPECT_LE(m.corners_base[0].head<2>().norm(), a.head<2>().norm()) << "trial " << trial;
    }
    EXPECT_GT(twice_area, 0.0) << "trial " << trial;
    for (int row = window.y; row < window.br().y; ++row) {
      for (int col = window.x; col < window.br().x; ++col) {
        if (mask.at<std::uint16_t>(row, col) == 0) continue;
        Eigen::Vector3d p_base;
        ASSERT_EQ(ipm_.PixelToGround(Eigen::Vector2d(col, row), &p_base), IpmStatus::kOk);
        ASSERT_TRUE(InsideRectangle(m.corners_base, p_base, 2e-3))
            << "trial " << trial << " pixel " << col << "," << row;
      }
    }
  }
  EXPECT_GT(extracted, 250);
}

}  // namespace
}  // namespace ipm_road_mapper
