// The view's ceiling (EvaluateViewCeiling): a GT lane whose far part no frame sees within the
// view range cannot be covered, a marking wider than the view cannot have its center where a
// map of its seen part puts it, and what the drive's masks never held does not count.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "common/test_scene.h"
#include "ipm_road_mapper/eval/evaluation.h"

namespace ipm_road_mapper {
namespace {

// 1280x720, fx 1000 (65 deg across), 1.5 m ahead of and above base_link, pitched 5 deg down:
// the ground is in the image from 4.75 m ahead of base_link. The vehicle drives along +x
// from x = 0 to 50 m, a frame every metre.
GroundTruth StraightDrive() {
  GroundTruth gt;
  gt.camera = test::Intrinsics1280x720();
  gt.T_base_cam_true = test::MountedCamera(0.0, 5.0 * M_PI / 180.0, 0.0);
  for (int k = 0; k <= 50; ++k) {
    GroundTruthFrame frame;
    frame.stamp = 0.05 * k;
    frame.T_map_base_true = test::PlanarPose(k, 0.0, 0.0);
    gt.frames.push_back(frame);
  }
  return gt;
}

GroundTruthLane Line(int id, double y, double x0, double x1) {
  GroundTruthLane lane;
  lane.id = id;
  lane.class_name = "lane_white_solid";
  for (double x = x0; x <= x1 + 1e-9; x += 0.1) lane.points_map.emplace_back(x, y, 0.0);
  return lane;
}

// An axis-aligned marking over [x0, x1] x [y0, y1], corners counter-clockwise.
GroundTruthMarking Rectangle(int id, double x0, double x1, double y0, double y1,
                             int visible_frames) {
  GroundTruthMarking m;
  m.id = id;
  m.class_id = 10;
  m.corners_map = {Eigen::Vector3d(x0, y0, 0.0), Eigen::Vector3d(x1, y0, 0.0),
                   Eigen::Vector3d(x1, y1, 0.0), Eigen::Vector3d(x0, y1, 0.0)};
  m.center_map = Eigen::Vector3d(0.5 * (x0 + x1), 0.5 * (y0 + y1), 0.0);
  m.visible_frames = visible_frames;
  return m;
}

TEST(ViewCeiling, LaneBeyondTheViewRangeIsUnreachable) {
  GroundTruth gt = StraightDrive();
  gt.lanes.push_back(Line(1, 1.75, 0.0, 60.0));    // seen from x 4.75 on
  gt.lanes.push_back(Line(2, 1.75, 60.0, 200.0));  // seen up to 40 m ahead of x 50 only
  const EvaluationOptions options;                 // view range 40 m
  const ViewCeilingMetrics c = EvaluateViewCeiling(gt, options);
  ASSERT_EQ(c.lanes.size(), 2u);
  EXPECT_NEAR(c.lanes[0].in_view_fraction, 55.25 / 60.0, 0.01);
  EXPECT_TRUE(c.lanes[0].reachable);
  EXPECT_NEAR(c.lanes[1].in_view_fraction, 30.0 / 140.0, 0.01);
  EXPECT_FALSE(c.lanes[1].reachable);
  EXPECT_EQ(c.lanes_reachable, 1);
  EXPECT_DOUBLE_EQ(c.lane_recall, 0.5);
  EXPECT_NEAR(c.lane_f1, 2.0 / 3.0, 1e-12);

  // A camera allowed to map ground 200 m away sees all of it.
  EvaluationOptions far = options;
  far.view_range_m = 200.0;
  const ViewCeilingMetrics c_far = EvaluateViewCeiling(gt, far);
  EXPECT_DOUBLE_EQ(c_far.lanes[1].in_view_fraction, 1.0);
  EXPECT_EQ(c_far.lanes_reachable, 2);
  EXPECT_DOUBLE_EQ(c_far.lane_f1, 1.0);
}

TEST(ViewCeiling, MarkingWiderThanTheViewIsUnreachable) {
  GroundTruth gt = StraightDrive();
  // A 50 m crossing at x 60-64 from y -5 to 45: its left end is never in the image within
  // 40 m, so the seen part's center lies meters right of the crossing's.
  gt.markings.push_back(Rectangle(1, 60.0, 64.0, -5.0, 45.0, 30));
  gt.markings.push_back(Rectangle(2, 30.0, 33.0, -0.25, 0.25, 30));   // a stripe, wholly seen
  gt.markings.push_back(Rectangle(3, 30.0, 33.0, 1.75, 2.25, 0));     // the masks never held it
  gt.markings.push_back(Rectangle(4, -30.0, -27.0, -0.25, 0.25, 5));  // behind every frame
  const ViewCeilingMetrics c = EvaluateViewCeiling(gt, EvaluationOptions());
  ASSERT_EQ(c.markings.size(), 4u);
  const ViewCeilingMarking& crossing = c.markings[0];
  EXPECT_GT(crossing.in_view_fraction, 0.3);
  EXPECT_LT(crossing.in_view_fraction, 0.7);
  EXPECT_GT(crossing.in_view_center_offset_m, 5.0);
  EXPECT_FALSE(crossing.reachable);
  EXPECT_NEAR(c.markings[1].in_view_fraction, 1.0, 1e-12);
  EXPECT_LT(c.markings[1].in_view_center_offset_m, 1e-6);
  EXPECT_TRUE(c.markings[1].reachable);
  EXPECT_NEAR(c.markings[2].in_view_fraction, 1.0, 1e-12);
  EXPECT_FALSE(c.markings[2].reachable);  // not in the recall's denominator either
  EXPECT_DOUBLE_EQ(c.markings[3].in_view_fraction, 0.0);
  EXPECT_TRUE(std::isnan(c.markings[3].in_view_center_offset_m));
  EXPECT_FALSE(c.markings[3].reachable);
  EXPECT_EQ(c.markings_visible, 3);
  EXPECT_EQ(c.markings_reachable, 1);
  EXPECT_NEAR(c.marking_recall, 1.0 / 3.0, 1e-12);

  // Moved so that the view covers it symmetrically, the crossing's seen part is centered.
  gt.markings[0] = Rectangle(1, 60.0, 64.0, -25.0, 25.0, 30);
  const ViewCeilingMetrics centered = EvaluateViewCeiling(gt, EvaluationOptions());
  EXPECT_LT(centered.markings[0].in_view_center_offset_m, 0.2);
  EXPECT_TRUE(centered.markings[0].reachable);
}

MapMarking MapRectangle(std::uint64_t id, double x0, double x1, double y0, double y1) {
  MapMarking m;
  m.id = id;
  m.class_id = 10;
  m.corners_map = {Eigen::Vector3d(x0, y0, 0.0), Eigen::Vector3d(x1, y0, 0.0),
                   Eigen::Vector3d(x1, y1, 0.0), Eigen::Vector3d(x0, y1, 0.0)};
  return m;
}

// A partial map element is judged against the part of its marking that was seen: the rectangle
// of the seen part matches, a whole-marking guess does not; a marking seen whole matches as
// its own center.
TEST(ViewCeiling, SeenPartsMatchWhatWasSeen) {
  GroundTruth gt = StraightDrive();
  gt.markings.push_back(Rectangle(1, 60.0, 64.0, -5.0, 45.0, 30));   // wider than the view
  gt.markings.push_back(Rectangle(2, 30.0, 33.0, -0.25, 0.25, 30));  // a stripe
  gt.markings.push_back(Rectangle(3, 30.0, 33.0, 1.75, 2.25, 0));    // never in the masks
  const EvaluationOptions options;
  const ViewCeilingMetrics ceiling = EvaluateViewCeiling(gt, options);
  const Eigen::Vector3d seen = ceiling.markings[0].in_view_center_map;
  ASSERT_TRUE(seen.allFinite());

  VectorMap map;
  // The seen part's rectangle, 0.3 m off across: on its seen part.
  map.markings.push_back(MapRectangle(7, 60.3, 64.3, -5.0, 2.0 * seen.y() + 5.0));
  map.markings.push_back(MapRectangle(8, 30.1, 33.1, -0.25, 0.25));
  SeenPartMetrics parts = EvaluateSeenParts(map, gt, ceiling, options);
  ASSERT_EQ(parts.gt_seen, 2);
  ASSERT_EQ(parts.markings.size(), 2u);
  EXPECT_TRUE(parts.markings[0].matched);
  EXPECT_EQ(parts.markings[0].map_id, 7u);
  EXPECT_NEAR(parts.markings[0].center_error_m, 0.3, 0.05);
  EXPECT_TRUE(parts.markings[1].matched);
  EXPECT_NEAR(parts.markings[1].center_error_m, 0.1, 1e-9);
  EXPECT_DOUBLE_EQ(parts.recall, 1.0);
  EXPECT_NEAR(parts.center_error_max_m, 0.3, 0.05);

  // The whole crossing drawn where the truth has it is no map of what was seen.
  map.markings[0] = MapRectangle(7, 60.0, 64.0, -5.0, 45.0);
  parts = EvaluateSeenParts(map, gt, ceiling, options);
  EXPECT_FALSE(parts.markings[0].matched);
  EXPECT_TRUE(std::isnan(parts.markings[0].center_error_m));
  EXPECT_EQ(parts.matched, 1);
  EXPECT_DOUBLE_EQ(parts.recall, 0.5);
}

// A hostile ground truth (a marking kilometres wide, lane points kilometres apart, NaN) is
// judged without a sample per centimetre of it.
TEST(ViewCeiling, AbsurdGroundTruthStaysCheap) {
  GroundTruth gt = StraightDrive();
  gt.markings.push_back(Rectangle(1, -5000.0, 5000.0, -5000.0, 5000.0, 30));
  gt.markings.push_back(Rectangle(2, 20.0, 300.0, -0.25, 0.25, 30));  // 280 m long
  gt.markings.push_back(Rectangle(3, 20.0, 21.0, -0.25, 0.25, 30));
  gt.markings.back().corners_map[2].x() = std::numeric_limits<double>::quiet_NaN();
  GroundTruthLane sparse;
  sparse.id = 1;
  for (int k = 0; k < 1000; ++k) sparse.points_map.emplace_back(1000.0 * k - 1e5, 1.0, 0.0);
  gt.lanes.push_back(sparse);
  const ViewCeilingMetrics c = EvaluateViewCeiling(gt, EvaluationOptions());
  ASSERT_EQ(c.markings.size(), 3u);
  EXPECT_FALSE(c.markings[0].reachable);
  EXPECT_TRUE(std::isnan(c.markings[0].in_view_center_offset_m));
  EXPECT_GT(c.markings[1].in_view_fraction, 0.0);  // its near part is in view
  EXPECT_LT(c.markings[1].in_view_fraction, 0.3);
  EXPECT_FALSE(c.markings[1].reachable);
  EXPECT_FALSE(c.markings[2].reachable);
  EXPECT_LT(c.lanes[0].in_view_fraction, 0.01);
}

TEST(ViewCeiling, EmptyDriveHasNoCeiling) {
  const ViewCeilingMetrics c = EvaluateViewCeiling(GroundTruth(), EvaluationOptions());
  EXPECT_TRUE(std::isnan(c.lane_recall));
  EXPECT_TRUE(std::isnan(c.lane_f1));
  EXPECT_TRUE(std::isnan(c.marking_recall));
}

TEST(ViewCeiling, ReportedByEvaluateMap) {
  GroundTruth gt = StraightDrive();
  gt.lanes.push_back(Line(1, 1.75, 0.0, 60.0));
  gt.markings.push_back(Rectangle(1, 60.0, 64.0, -5.0, 45.0, 30));
  const Metrics metrics = EvaluateMap(VectorMap(), gt, EvaluationOptions());
  const nlohmann::json j = MetricsToJson(metrics);
  EXPECT_EQ(j.at("ceiling_lanes_reachable"), 1);
  EXPECT_DOUBLE_EQ(j.at("ceiling_lane_f1").get<double>(), 1.0);
  EXPECT_EQ(j.at("ceiling_markings_reachable"), 0);
  EXPECT_DOUBLE_EQ(j.at("ceiling_view_range_m").get<double>(), 40.0);
  ASSERT_EQ(j.at("ceiling_markings").size(), 1u);
  EXPECT_FALSE(j.at("ceiling_markings")[0].at("reachable").get<bool>());
  EXPECT_NE(FormatMetricsTable(metrics).find("The view's ceiling"), std::string::npos);
}

}  // namespace
}  // namespace ipm_road_mapper
