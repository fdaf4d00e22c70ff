// Route repetition (`repeat_count`, long drives): the copies are laid end to end with the
// same geometry, relief and markings, and the long benchmark scenario is public_road x 33.
#include <gtest/gtest.h>

#include <string>

#include "ipm_road_mapper/sim/road.h"
#include "ipm_road_mapper/sim/scenario.h"
#include "ipm_road_mapper/sim/world.h"

namespace ipm_road_mapper {
namespace sim {
namespace {

const std::string kSource = IRM_SOURCE_DIR;

ClassTable Classes() { return ClassTable::LoadFile(kSource + "/config/classes.yaml"); }

// A 100 m route (straight + left arc) with a hill, a bump and two markings; `extra` is
// appended at the top level.
std::string Route(const std::string& extra) {
  return "name: t\n"
         "road:\n"
         "  segments: [{type: straight, length_m: 40}, {type: arc, radius_m: 120, angle_deg: "
         "28.64788975654116}]\n"
         "  surface:\n"
         "    grade: [{s_m: 10, grade_pct: 0}, {s_m: 30, grade_pct: 2}, {s_m: 60, grade_pct: 0}]\n"
         "    bumps: [{s_m: 80, height_m: 0.05}]\n"
         "markings:\n"
         "  - {class: arrow_straight, s_m: 20, lanes: [1]}\n"
         "  - {class: stop_line, s_m: 70, offset_m: 0, length_m: 0.4, width_m: 9.8}\n" +
         extra;
}

ScenarioOptions Load(const std::string& yaml) {
  return LoadScenario(OptionsReader(YAML::Load(yaml), ""), Classes());
}

// The OptionsError message of loading `yaml` ("" when it loads).
std::string ErrorOf(const std::string& yaml) {
  try {
    Load(yaml);
  } catch (const OptionsError& e) {
    return e.what();
  }
  return "";
}

TEST(SimRepeat, DefaultIsOneCopy) {
  const ScenarioOptions o = Load(Route(""));
  EXPECT_EQ(o.repeat_count, 1);
  EXPECT_EQ(o.road.segments.size(), 2u);
  EXPECT_EQ(o.markings.size(), 2u);
  EXPECT_NEAR(o.vehicle.end_s_m, 90.0, 1e-9);
}

TEST(SimRepeat, CopiesAreShiftedByTheRoadLength) {
  const ScenarioOptions o = Load(Route("repeat_count: 3\n"));
  ASSERT_EQ(o.road.segments.size(), 6u);
  EXPECT_TRUE(o.road.segments[3].is_arc);
  EXPECT_DOUBLE_EQ(o.road.segments[5].length_m, o.road.segments[1].length_m);
  ASSERT_EQ(o.road.surface.grade.size(), 9u);
  EXPECT_NEAR(o.road.surface.grade[3].s_m, 110.0, 1e-9);
  EXPECT_NEAR(o.road.surface.grade[8].s_m, 260.0, 1e-9);
  EXPECT_DOUBLE_EQ(o.road.surface.grade[7].grade_pct, 2.0);
  ASSERT_EQ(o.road.surface.bumps.size(), 3u);
  EXPECT_NEAR(o.road.surface.bumps[2].s_m, 280.0, 1e-9);
  ASSERT_EQ(o.markings.size(), 6u);
  EXPECT_NEAR(o.markings[4].s_m, 220.0, 1e-9);
  EXPECT_EQ(o.markings[5].class_name, "stop_line");
  EXPECT_NEAR(o.markings[5].s_m, 270.0, 1e-9);
  EXPECT_NEAR(o.vehicle.end_s_m, 290.0, 1e-9);  // default end follows the repeated road
}

TEST(SimRepeat, EveryCopyHasTheSameShapeAndRelief) {
  const ScenarioOptions one = Load(Route(""));
  const ScenarioOptions three = Load(Route("repeat_count: 3\n"));
  const RoadModel road(three.road);
  const RoadModel base(one.road);
  ASSERT_NEAR(road.length(), 300.0, 1e-9);
  // Same curvature, the same turn and the same climb per copy: the height difference over
  // one copy is a constant (the hill's rise), and the heading advances by the arc's angle.
  const double rise = base.ProfileHeight(100.0) - base.ProfileHeight(0.0);
  EXPECT_GT(rise, 0.3);
  for (double s = 0.5; s < 100.0; s += 3.7) {
    for (int copy = 1; copy < 3; ++copy) {
      const double s_copy = s + 100.0 * copy;
      EXPECT_DOUBLE_EQ(road.Centerline(s_copy).curvature, base.Centerline(s).curvature) << s;
      EXPECT_NEAR(road.Centerline(s_copy).heading - road.Centerline(s).heading, 0.5 * copy, 1e-9);
      EXPECT_NEAR(road.ProfileHeight(s_copy) - road.ProfileHeight(s), rise * copy, 1e-9) << s;
    }
  }
  // The world: three times the markings, each copy the same shape at its shifted s.
  const SimWorld world_one(one, Classes(), 0.0, 100.0);
  const SimWorld world(three, Classes(), 0.0, 300.0);
  ASSERT_EQ(world.markings().size(), 3 * world_one.markings().size());
  for (std::size_t i = 0; i < world_one.markings().size(); ++i) {
    const SimMarking& a = world_one.markings()[i];
    const SimMarking& b = world.markings()[i + 2 * world_one.markings().size()];
    EXPECT_EQ(a.class_name, b.class_name);
    EXPECT_NEAR(b.s_origin - a.s_origin, 200.0, 1e-9);
    EXPECT_NEAR((b.corners_map[0] - b.corners_map[2]).norm(),
                (a.corners_map[0] - a.corners_map[2]).norm(), 1e-6);
  }
}

TEST(SimRepeat, BadCountsAndUnrepeatableKnotsAreErrors) {
  EXPECT_NE(ErrorOf(Route("repeat_count: 0\n")).find("repeat_count"), std::string::npos);
  const std::string span = ErrorOf(
      "name: t\nroad:\n  segments: [{type: straight, length_m: 100}]\n"
      "  surface: {grade: [{s_m: 0, grade_pct: 0}, {s_m: 100, grade_pct: 1}]}\n"
      "repeat_count: 2\n");
  EXPECT_NE(span.find("repeat_count: road.surface.grade knots span"), std::string::npos) << span;
  // One copy never complains about the knots.
  EXPECT_EQ(ErrorOf("name: t\nroad:\n  segments: [{type: straight, length_m: 100}]\n"
                    "  surface: {grade: [{s_m: 0, grade_pct: 0}, {s_m: 100, grade_pct: 1}]}\n"),
            "");
}

TEST(SimRepeat, LongScenarioIsPublicRoadThirtyThreeTimesWithoutImages) {
  const ScenarioOptions base =
      LoadScenarioFile(kSource + "/config/scenarios/public_road.yaml", Classes());
  const ScenarioOptions o =
      LoadScenarioFile(kSource + "/config/scenarios/public_road_long.yaml", Classes());
  EXPECT_EQ(o.name, "public_road_long");
  EXPECT_EQ(o.repeat_count, 33);
  EXPECT_EQ(o.camera.image_every_n_frames, 0);
  EXPECT_EQ(o.markings.size(), 33 * base.markings.size());
  const double length_m = RoadModel(o.road).length();
  EXPECT_NEAR(length_m, 33.0 * RoadModel(base.road).length(), 1e-6);
  EXPECT_GT(o.vehicle.end_s_m - o.vehicle.start_s_m, 10000.0);  // a 10 km drive
  EXPECT_DOUBLE_EQ(o.odometry.jitter_xy_m, base.odometry.jitter_xy_m);
  EXPECT_DOUBLE_EQ(o.segmentation.boundary_jitter_px, base.segmentation.boundary_jitter_px);
  EXPECT_DOUBLE_EQ(o.camera.mount.pitch_deg, base.camera.mount.pitch_deg);
}

}  // namespace
}  // namespace sim
}  // namespace ipm_road_mapper
