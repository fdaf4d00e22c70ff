#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "../../src/core/frontend/instance_extraction_runs.h"  // BoundingRectangle
#include "common/mask_test_utils.h"
#include "ipm_road_mapper/core/frontend/instance_extraction.h"

namespace ipm_road_mapper {
namespace {

using test::EmptyMask;
using test::GroundRectangle;
using test::kTestHeight;
using test::kTestWidth;
using test::RenderGroundRectangle;
using test::RenderLaneStrip;
using test::TestIpm;

constexpr double kDeg = M_PI / 180.0;
// Mask values of config/classes.yaml classes: 1 lane_white_solid, 2 lane_white_dashed,
// 10 arrow_straight, 21 stop_line; class 50 is not in the table.
constexpr std::uint16_t kSolidLane = 1 * kInstanceIdFactor;
constexpr std::uint16_t kDashedLane = 2 * kInstanceIdFactor;
constexpr std::uint16_t kArrow = 10 * kInstanceIdFactor;
constexpr std::uint16_t kStopLine = 21 * kInstanceIdFactor;
constexpr std::uint16_t kUnknownClass = 50 * kInstanceIdFactor;

ClassTable TestClasses() {
  return ClassTable::LoadFile(std::string(IRM_SOURCE_DIR) + "/config/classes.yaml");
}

// Milliseconds since `start`.
double MsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

// Timing bounds hold for optimized builds only (NDEBUG, as CMake's Release sets); other
// builds print the time without asserting it.
void ExpectFasterThan(double ms, double limit_ms) {
#ifdef NDEBUG
  EXPECT_LT(ms, limit_ms);
#else
  (void)ms;
  (void)limit_ms;
#endif
}

class InstanceExtractionTest : public ::testing::Test {
 protected:
  FrameObservations Extract(const cv::Mat& mask) const {
    return ExtractObservations(mask, classes_, ipm_, error_model_, options_);
  }

  // Extracted markings of a mask holding one ground rectangle.
  FrameObservations ExtractRectangle(const Eigen::Vector2d& center_base, double length_m,
                                     double width_m, double yaw_rad, std::uint16_t value) const {
    cv::Mat mask = EmptyMask();
    RenderGroundRectangle(ipm_, center_base, length_m, width_m, yaw_rad, value, &mask);
    return Extract(mask);
  }

  // Largest distance between the extracted corners and the true rectangle's corners in
  // canonical order (nearest to the origin first, counter-clockwise).
  static double MaxCornerError(const MarkingObservation& marking,
                               std::vector<Eigen::Vector2d> truth_ccw) {
    const auto nearest = std::min_element(truth_ccw.begin(), truth_ccw.end(),
                                          [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
                                            return a.squaredNorm() < b.squaredNorm();
                                          });
    std::rotate(truth_ccw.begin(), nearest, truth_ccw.end());
    double max_error = 0.0;
    for (int i = 0; i < 4; ++i) {
      max_error = std::max(max_error, (marking.corners_base[i].head<2>() - truth_ccw[i]).norm());
    }
    return max_error;
  }

  ClassTable classes_ = TestClasses();
  Ipm ipm_ = TestIpm();
  IpmErrorModel error_model_;
  ExtractionOptions options_;
};

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

TEST_F(InstanceExtractionTest, StraightLaneCenterline) {
  cv::Mat mask = EmptyMask();
  RenderLaneStrip(ipm_, 1.8, 4.0, 40.0, 0.15, kSolidLane + 2, &mask);
  const FrameObservations obs = Extract(mask);
  ASSERT_EQ(obs.lanes.size(), 1u);
  EXPECT_TRUE(obs.markings.empty());
  const LaneObservation& lane = obs.lanes[0];
  EXPECT_EQ(lane.class_id, 1);
  EXPECT_EQ(lane.instance_value, kSolidLane + 2);
  EXPECT_EQ(lane.pixel_count, cv::countNonZero(mask));
  ASSERT_GE(lane.points.size(), 50u);

  int increasing_scores = 0;
  for (std::size_t i = 0; i < lane.points.size(); ++i) {
    const LanePoint& p = lane.points[i];
    EXPECT_NEAR(p.p_base.y(), 1.8, 0.05) << "point " << i << " at x " << p.p_base.x();
    EXPECT_EQ(p.p_base.z(), 0.0);
    EXPECT_GE(p.p_base.x(), 4.0 - 0.1);
    EXPECT_LE(p.p_base.x(), 40.0 + 0.5);
    EXPECT_GT(p.score, 0.0);
    if (i == 0) continue;
    const LanePoint& previous = lane.points[i - 1];
    EXPECT_EQ(previous.uv.y() - p.uv.y(), options_.lane_row_step) << "point " << i;
    EXPECT_GT(p.p_base.x(), previous.p_base.x());
    if (p.score > previous.score) ++increasing_scores;
  }
  // Bottom (near) first; the nearest point is at the strip's near end.
  EXPECT_NEAR(lane.points.front().p_base.x(), 4.0, 0.1);
  EXPECT_GT(lane.points.back().p_base.x(), 35.0);
  EXPECT_GE(increasing_scores, static_cast<int>(0.9 * (lane.points.size() - 1)));
  EXPECT_GT(lane.points.back().score, 10.0 * lane.points.front().score);
}

TEST_F(InstanceExtractionTest, DashedLaneIsOneObservation) {
  cv::Mat mask = EmptyMask();
  for (double x = 5.0; x < 40.0; x += 9.0) {
    RenderLaneStrip(ipm_, -1.8, x, x + 3.0, 0.15, kDashedLane + 1, &mask);
  }
  const FrameObservations obs = Extract(mask);
  ASSERT_EQ(obs.lanes.size(), 1u);
  EXPECT_EQ(obs.counters.instances_seen, 1u);
  const LaneObservation& lane = obs.lanes[0];
  ASSERT_GE(lane.points.size(), 20u);
  EXPECT_LT(lane.points.front().p_base.x(), 6.0);
  EXPECT_GT(lane.points.back().p_base.x(), 30.0);
  for (std::size_t i = 0; i < lane.points.size(); ++i) {
    EXPECT_NEAR(lane.points[i].p_base.y(), -1.8, 0.05);
    if (i > 0) {
      EXPECT_LT(lane.points[i].uv.y(), lane.points[i - 1].uv.y());
    }
  }
}

TEST_F(InstanceExtractionTest, LaneBeyondRangeIsDegenerate) {
  options_.min_lane_pixels = 10;
  cv::Mat mask = EmptyMask();
  RenderLaneStrip(ipm_, 1.8, 48.0, 60.0, 0.5, kSolidLane, &mask);
  const FrameObservations obs = Extract(mask);
  EXPECT_TRUE(obs.lanes.empty());
  EXPECT_EQ(obs.counters.dropped_degenerate, 1u);
}

TEST(ValidateMaskTest, RejectsWrongTypeSizeAndEmpty) {
  EXPECT_EQ(ValidateMask(EmptyMask(), kTestWidth, kTestHeight), "");
  const std::string wrong_8u =
      ValidateMask(cv::Mat(kTestHeight, kTestWidth, CV_8UC1), kTestWidth, kTestHeight);
  EXPECT_NE(wrong_8u.find("8UC1"), std::string::npos) << wrong_8u;
  EXPECT_NE(wrong_8u.find("16UC1"), std::string::npos) << wrong_8u;
  const std::string wrong_3c =
      ValidateMask(cv::Mat(kTestHeight, kTestWidth, CV_16UC3), kTestWidth, kTestHeight);
  EXPECT_NE(wrong_3c.find("16UC3"), std::string::npos) << wrong_3c;
  EXPECT_NE(
      ValidateMask(cv::Mat(kTestHeight, kTestWidth, CV_32F), kTestWidth, kTestHeight).find("32FC1"),
      std::string::npos);
  const std::string wrong_size = ValidateMask(cv::Mat(480, 640, CV_16UC1), kTestWidth, kTestHeight);
  EXPECT_EQ(wrong_size, "mask is 640x480, camera is 1280x720");
  const std::string empty = ValidateMask(cv::Mat(), kTestWidth, kTestHeight);
  EXPECT_NE(empty.find("empty"), std::string::npos) << empty;
  for (const std::string& reason : {wrong_8u, wrong_3c, wrong_size, empty}) {
    EXPECT_EQ(reason.find('\n'), std::string::npos);
  }
}

TEST_F(InstanceExtractionTest, UnusableMaskGivesNothingWithoutCrash) {
  EXPECT_EQ(Extract(cv::Mat()).counters.instances_seen, 0u);
  EXPECT_EQ(
      Extract(cv::Mat(kTestHeight, kTestWidth, CV_8UC1, cv::Scalar(200))).counters.instances_seen,
      0u);
}

TEST_F(InstanceExtractionTest, NonContinuousMaskView) {
  // A view into a wider buffer (rows not contiguous) must give the same result.
  cv::Mat wide(kTestHeight, kTestWidth + 64, CV_16UC1, cv::Scalar(0));
  cv::Mat view = wide(cv::Rect(32, 0, kTestWidth, kTestHeight));
  RenderGroundRectangle(ipm_, {10.0, 0.0}, 2.0, 0.5, 20 * kDeg, kArrow, &view);
  ASSERT_FALSE(view.isContinuous());
  const FrameObservations a = Extract(view);
  const FrameObservations b = Extract(view.clone());
  ASSERT_EQ(a.markings.size(), 1u);
  ASSERT_EQ(b.markings.size(), 1u);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(a.markings[0].corners_uv[i], b.markings[0].corners_uv[i]);
}

// Sum of every outcome of an instance: each seen instance is accounted for exactly once.
std::uint64_t Accounted(const FrameObservations& obs) {
  const ExtractionCounters& c = obs.counters;
  return obs.markings.size() + obs.lanes.size() + c.dropped_unknown_class + c.dropped_tiny +
         c.dropped_border + c.dropped_range + c.dropped_degenerate + c.dropped_instance_limit +
         c.dropped_oversized + c.dropped_wide_lane + c.dropped_absurd_frame;
}

TEST_F(InstanceExtractionTest, AllForegroundMaskIsBounded) {
  // Every pixel one lane instance: handled like a (very wide) lane, no crash.
  const auto start = std::chrono::steady_clock::now();
  const FrameObservations lane =
      Extract(cv::Mat(kTestHeight, kTestWidth, CV_16UC1, cv::Scalar(kSolidLane + 1)));
  const double lane_ms = MsSince(start);
  EXPECT_EQ(lane.counters.instances_seen, 1u);
  EXPECT_LE(lane.lanes.size(), 1u);
  // Every pixel one marking instance: cut by the border everywhere and the horizon, its
  // part in range centred beyond max_marking_range_m: dropped, counted once.
  const FrameObservations marking =
      Extract(cv::Mat(kTestHeight, kTestWidth, CV_16UC1, cv::Scalar(kArrow + 1)));
  EXPECT_EQ(marking.counters.instances_seen, 1u);
  EXPECT_EQ(Accounted(marking), 1u);
  EXPECT_TRUE(marking.markings.empty());
  std::cout << "[ info ] all-foreground lane mask: " << lane_ms << " ms\n";
  ExpectFasterThan(lane_ms, 200.0);
}

// The n-th distinct instance value: classes 1..65 in turn, instance indices 0..999,
// skipping values above 65535.
std::vector<std::uint16_t> DistinctValues(int n) {
  std::vector<std::uint16_t> values;
  for (int index = 0; static_cast<int>(values.size()) < n && index < kInstanceIdFactor; ++index) {
    for (int class_id = 1; class_id <= kMaxClassId && static_cast<int>(values.size()) < n;
         ++class_id) {
      const int value = class_id * kInstanceIdFactor + index;
      if (value <= 65535) values.push_back(static_cast<std::uint16_t>(value));
    }
  }
  return values;
}

TEST_F(InstanceExtractionTest, TenThousandInstancesInTilesAreBounded) {
  options_.min_marking_pixels = 20;  // let the small tiles through to the instance limit
  options_.min_lane_pixels = 20;
  options_.min_lane_points = 2;
  options_.max_plausible_instances = 100000;  // this test is about the instance limit
  const std::vector<std::uint16_t> values = DistinctValues(10000);
  ASSERT_EQ(values.size(), 10000u);
  cv::Mat mask = EmptyMask();
  const int tile = 8, tiles_per_row = kTestWidth / tile;
  for (int i = 0; i < 10000; ++i) {
    mask(cv::Rect((i % tiles_per_row) * tile, (i / tiles_per_row) * tile, tile, tile))
        .setTo(values[i]);
  }
  const auto start = std::chrono::steady_clock::now();
  const FrameObservations obs = Extract(mask);
  const double ms = MsSince(start);
  std::cout << "[ info ] 10,000 tiled instances: " << ms << " ms, "
            << obs.counters.dropped_instance_limit << " over the limit\n";
  EXPECT_EQ(obs.counters.instances_seen, 10000u);
  EXPECT_GT(obs.counters.dropped_instance_limit, 0u);
  const std::uint64_t processed = obs.markings.size() + obs.lanes.size() +
                                  obs.counters.dropped_range + obs.counters.dropped_degenerate;
  EXPECT_EQ(processed, static_cast<std::uint64_t>(options_.max_instances_per_frame));
  EXPECT_EQ(Accounted(obs), 10000u);
  ExpectFasterThan(ms, 200.0);
}

TEST_F(InstanceExtractionTest, TenThousandScatteredInstancesAreBounded) {
  // Every pixel a different instance than its neighbor, each instance spread over the
  // whole image (bounding boxes all image-sized): the worst case for per-ROI work.
  const std::vector<std::uint16_t> values = DistinctValues(10000);
  cv::Mat mask = EmptyMask();
  for (int row = 0; row < kTestHeight; ++row) {
    for (int col = 0; col < kTestWidth; ++col) {
      mask.at<std::uint16_t>(row, col) = values[(row * 7919 + col) % values.size()];
    }
  }
  options_.min_marking_pixels = 20;
  options_.min_lane_pixels = 20;
  options_.max_plausible_instances = 100000;  // the geometry's worst case, not the frame check
  const auto start = std::chrono::steady_clock::now();
  const FrameObservations obs = Extract(mask);
  const double ms = MsSince(start);
  std::cout << "[ info ] 10,000 scattered instances: " << ms << " ms\n";
  EXPECT_EQ(obs.counters.instances_seen, 10000u);
  EXPECT_EQ(Accounted(obs), 10000u);
  EXPECT_LE(obs.markings.size() + obs.lanes.size(),
            static_cast<std::size_t>(options_.max_instances_per_frame));
  ExpectFasterThan(ms, 400.0);  // the adversarial case: 921,600 one-pixel runs
}

TEST_F(InstanceExtractionTest, InstanceLimitKeepsTheLargest) {
  options_.max_instances_per_frame = 1;
  cv::Mat mask = EmptyMask();
  RenderGroundRectangle(ipm_, {12.0, -2.0}, 2.0, 0.5, 0.0, kArrow + 1, &mask);
  RenderGroundRectangle(ipm_, {9.0, 1.5}, 3.0, 1.0, 0.0, kArrow + 2, &mask);
  const FrameObservations obs = Extract(mask);
  ASSERT_EQ(obs.markings.size(), 1u);
  EXPECT_EQ(obs.markings[0].instance_value, kArrow + 2);
  EXPECT_EQ(obs.counters.dropped_instance_limit, 1u);
}

// A realistic frame: four lanes (two dashed) and a few markings.
cv::Mat RealisticMask(const Ipm& ipm) {
  cv::Mat mask = EmptyMask();
  RenderLaneStrip(ipm, 5.4, 3.5, 45.0, 0.15, kSolidLane + 0, &mask);
  for (double x = 4.0; x < 45.0; x += 9.0) {
    RenderLaneStrip(ipm, 1.8, x, x + 3.0, 0.15, kDashedLane + 1, &mask);
    RenderLaneStrip(ipm, -1.8, x + 2.0, x + 5.0, 0.15, kDashedLane + 2, &mask);
  }
  RenderLaneStrip(ipm, -5.4, 3.5, 45.0, 0.15, kSolidLane + 3, &mask);
  RenderGroundRectangle(ipm, {8.0, 0.0}, 3.0, 0.6, 0.0, kArrow + 0, &mask);
  RenderGroundRectangle(ipm, {15.0, -3.6}, 3.0, 0.6, 0.05, kArrow + 1, &mask);
  RenderGroundRectangle(ipm, {20.0, 3.6}, 0.4, 3.4, 0.0, kStopLine + 0, &mask);
  RenderGroundRectangle(ipm, {22.0, 0.0}, 2.5, 1.0, 0.0, 23 * kInstanceIdFactor, &mask);
  return mask;
}

TEST_F(InstanceExtractionTest, RealisticFrameTiming) {
  const cv::Mat mask = RealisticMask(ipm_);
  FrameObservations obs = Extract(mask);  // warm-up
  EXPECT_EQ(obs.lanes.size(), 4u);
  EXPECT_EQ(obs.markings.size(), 4u);
  EXPECT_EQ(Accounted(obs), obs.counters.instances_seen);
  constexpr int kRuns = 50;
  const auto start = std::chrono::steady_clock::now();
  std::size_t points = 0;
  for (int run = 0; run < kRuns; ++run) {
    obs = Extract(mask);
    for (const LaneObservation& lane : obs.lanes) points += lane.points.size();
  }
  const double ms = MsSince(start) / kRuns;
  std::cout << "[ info ] realistic 1280x720 frame (4 lanes, 4 markings, " << points / kRuns
            << " lane points): " << ms << " ms per extraction (mean of " << kRuns << ")\n";
  ExpectFasterThan(ms, 200.0);
}

TEST(ExtractionOptionsTest, LoadsValuesAndRejectsUnknownKeys) {
  OptionsReader root(YAML::Load("extraction: {lane_row_step: 6, max_marking_range_m: 30.0}"), "");
  const ExtractionOptions o = LoadExtractionOptions(root.Child("extraction"));
  EXPECT_EQ(o.lane_row_step, 6);
  EXPECT_EQ(o.max_marking_range_m, 30.0);
  EXPECT_EQ(o.min_marking_pixels, ExtractionOptions().min_marking_pixels);

  OptionsReader typo(YAML::Load("extraction: {lane_row_stepp: 6}"), "");
  try {
    LoadExtractionOptions(typo.Child("extraction"));
    FAIL() << "unknown key accepted";
  } catch (const OptionsError& e) {
    EXPECT_NE(std::string(e.what()).find("extraction.lane_row_stepp"), std::string::npos)
        << e.what();
  }
  OptionsReader bad(YAML::Load("extraction: {lane_row_step: 0}"), "");
  try {
    LoadExtractionOptions(bad.Child("extraction"));
    FAIL() << "lane_row_step 0 accepted";
  } catch (const OptionsError& e) {
    EXPECT_NE(std::string(e.what()).find("extraction.lane_row_step"), std::string::npos)
        << e.what();
  }
}

TEST(ExtractionCountersTest, AddSumsEveryCounter) {
  ExtractionCounters a, b;
  a.instances_seen = 1;
  a.dropped_unknown_class = 2;
  a.dropped_tiny = 3;
  a.dropped_border = 4;
  a.dropped_range = 5;
  a.dropped_degenerate = 6;
  a.dropped_instance_limit = 7;
  a.dropped_oversized = 8;
  a.dropped_wide_lane = 9;
  a.dropped_absurd_frame = 10;
  a.lane_runs_too_wide = 11;
  a.frames_too_many_instances = 12;
  a.frames_too_much_coverage = 13;
  b.Add(a);
  b.Add(a);
  EXPECT_EQ(b.instances_seen, 2u);
  EXPECT_EQ(b.dropped_unknown_class, 4u);
  EXPECT_EQ(b.dropped_tiny, 6u);
  EXPECT_EQ(b.dropped_border, 8u);
  EXPECT_EQ(b.dropped_range, 10u);
  EXPECT_EQ(b.dropped_degenerate, 12u);
  EXPECT_EQ(b.dropped_instance_limit, 14u);
  EXPECT_EQ(b.dropped_oversized, 16u);
  EXPECT_EQ(b.dropped_wide_lane, 18u);
  EXPECT_EQ(b.dropped_absurd_frame, 20u);
  EXPECT_EQ(b.lane_runs_too_wide, 22u);
  EXPECT_EQ(b.frames_too_many_instances, 24u);
  EXPECT_EQ(b.frames_too_much_coverage, 26u);
}

}  // namespace
}  // namespace ipm_road_mapper
