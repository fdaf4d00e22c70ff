// Scenario loading: the shipped scenarios load, and typos, bad values and unknown class
// names are errors that name the key.
#include <gtest/gtest.h>

#include <string>

#include "ipm_road_mapper/sim/scenario.h"
#include "ipm_road_mapper/sim/world.h"

namespace ipm_road_mapper {
namespace sim {
namespace {

const std::string kSource = IRM_SOURCE_DIR;

ClassTable Classes() { return ClassTable::LoadFile(kSource + "/config/classes.yaml"); }

// A minimal valid scenario, with `extra` appended (YAML at the top level).
std::string Minimal(const std::string& extra = "") {
  return "name: t\n"
         "road:\n"
         "  segments: [{type: straight, length_m: 100}]\n" +
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

TEST(SimScenario, ShippedScenariosLoad) {
  for (const char* name : {"public_road", "port", "hilly", "urban", "curvy"}) {
    const std::string path = kSource + "/config/scenarios/" + name + ".yaml";
    ScenarioOptions o;
    ASSERT_NO_THROW(o = LoadScenarioFile(path, Classes())) << path;
    EXPECT_EQ(o.name, name);
    EXPECT_FALSE(o.markings.empty());
    EXPECT_EQ(static_cast<int>(o.road.line_class_ids.size()), o.road.lanes + 1);
  }
}

TEST(SimScenario, MinimalScenarioGetsDocumentedDefaults) {
  const ScenarioOptions o = Load(Minimal());
  EXPECT_EQ(o.road.lanes, 3);
  EXPECT_DOUBLE_EQ(o.road.lane_width_m, 3.5);
  EXPECT_EQ(o.road.line_classes.front(), "lane_white_solid");
  EXPECT_EQ(o.road.line_classes[1], "lane_white_dashed");
  EXPECT_EQ(o.camera.intrinsics.width, 1280);
  EXPECT_EQ(o.camera.intrinsics.height, 720);
  EXPECT_DOUBLE_EQ(o.camera.rate_hz, 20.0);
  EXPECT_EQ(o.camera.frame_id, "camera_optical");
  EXPECT_DOUBLE_EQ(o.odometry.rate_hz, 50.0);
  EXPECT_DOUBLE_EQ(o.vehicle.end_s_m, 90.0);  // road length - 10 m
  EXPECT_DOUBLE_EQ(o.start_time_s, 1000.0);
}

TEST(SimScenario, ArcLengthFollowsRadiusAndAngle) {
  const ScenarioOptions o =
      Load("name: t\nroad:\n  segments: [{type: arc, radius_m: 100, angle_deg: -90}]\n");
  ASSERT_EQ(o.road.segments.size(), 1u);
  EXPECT_NEAR(o.road.segments[0].length_m, 50.0 * M_PI, 1e-9);
}

TEST(SimScenario, UnknownKeysNameTheirPath) {
  EXPECT_NE(ErrorOf(Minimal("speed: 3\n")).find("speed: unknown key"), std::string::npos);
  EXPECT_NE(ErrorOf("name: t\nroad:\n  segments: [{type: straight, length_m: 100}]\n"
                    "  lane_widht_m: 3\n")
                .find("road.lane_widht_m: unknown key"),
            std::string::npos);
  EXPECT_NE(ErrorOf(Minimal("vehicle: {pitch_amplitude: 1}\n"))
                .find("vehicle.pitch_amplitude: unknown key"),
            std::string::npos);
  EXPECT_NE(ErrorOf(Minimal("markings: [{class: diamond, s_m: 10, size: 2}]\n"))
                .find("markings[0].size: unknown key"),
            std::string::npos);
  EXPECT_NE(ErrorOf(Minimal("camera: {mount: {pitch: 3}}\n")).find("camera.mount.pitch"),
            std::string::npos);
}

TEST(SimScenario, BadValuesNameTheirKey) {
  EXPECT_NE(ErrorOf("name: t\nroad:\n  segments: [{type: straight, length_m: 100}]\n"
                    "  lanes: 0\n")
                .find("road.lanes"),
            std::string::npos);
  EXPECT_NE(ErrorOf("name: t\nroad:\n  segments: [{type: spiral, length_m: 100}]\n")
                .find("road.segments[0].type"),
            std::string::npos);
  EXPECT_NE(ErrorOf("name: t\nroad:\n  segments: [{type: arc, radius_m: -5, angle_deg: 9}]\n")
                .find("road.segments[0].radius_m"),
            std::string::npos);
  EXPECT_NE(ErrorOf(Minimal("camera: {distortion: [0.1, 0.0]}\n")).find("camera.distortion"),
            std::string::npos);
  EXPECT_NE(ErrorOf(Minimal("camera: {fx: abc}\n")).find("camera.fx"), std::string::npos);
  EXPECT_NE(ErrorOf(Minimal("segmentation: {missed_instance_prob: 1.5}\n"))
                .find("segmentation.missed_instance_prob"),
            std::string::npos);
  EXPECT_NE(ErrorOf(Minimal("vehicle: {lane: 3}\n")).find("vehicle.lane"), std::string::npos);
  EXPECT_NE(ErrorOf(Minimal("markings: [{class: diamond, s_m: 10, lanes: [5]}]\n"))
                .find("markings[0].lanes"),
            std::string::npos);
  EXPECT_NE(ErrorOf(Minimal("markings: [{class: speed_limit, s_m: 10, text: 6a}]\n"))
                .find("markings[0].text"),
            std::string::npos);
  EXPECT_NE(ErrorOf(Minimal("vehicle: {start_s_m: 95}\n")).find("vehicle.end_s_m"),
            std::string::npos);
  EXPECT_NE(ErrorOf("road:\n  segments: [{type: straight, length_m: 100}]\n").find("name"),
            std::string::npos);
  const std::string road = "name: t\nroad:\n  segments: [{type: straight, length_m: 100}]\n";
  EXPECT_NE(ErrorOf(road + "  surface: {crown_pct: -1}\n").find("road.surface.crown_pct"),
            std::string::npos);
  EXPECT_NE(ErrorOf(road + "  surface: {crown_pct: 12}\n").find("road.surface.crown_pct"),
            std::string::npos);
  EXPECT_EQ(
      Load(road + "  surface: {crown_pct: 2, crown_offset_m: 1.75}\n").road.surface.crown_offset_m,
      1.75);
}

TEST(SimScenario, UnknownOrWrongKindClassNamesAreErrors) {
  const std::string unknown = ErrorOf(Minimal("markings: [{class: arow_left, s_m: 10}]\n"));
  EXPECT_NE(unknown.find("markings[0].class"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("arow_left"), std::string::npos) << unknown;
  const std::string lane_as_marking =
      ErrorOf(Minimal("markings: [{class: lane_white_solid, s_m: 10}]\n"));
  EXPECT_NE(lane_as_marking.find("markings[0].class"), std::string::npos) << lane_as_marking;
  const std::string bad_line = ErrorOf(
      "name: t\nroad:\n  segments: [{type: straight, length_m: 100}]\n  lanes: 1\n"
      "  line_classes: [lane_white_solid, lane_purple]\n");
  EXPECT_NE(bad_line.find("road.line_classes[1]"), std::string::npos) << bad_line;
  const std::string count = ErrorOf(
      "name: t\nroad:\n  segments: [{type: straight, length_m: 100}]\n  lanes: 2\n"
      "  line_classes: [lane_white_solid]\n");
  EXPECT_NE(count.find("road.line_classes"), std::string::npos) << count;
}

TEST(SimScenario, OverlappingMarkingsAreRejected) {
  const ScenarioOptions o =
      Load(Minimal("markings:\n"
                   "  - {class: diamond, s_m: 50, lanes: [1], length_m: 3}\n"
                   "  - {class: arrow_straight, s_m: 52, lanes: [1], length_m: 5}\n"));
  try {
    SimWorld world(o, Classes(), 0.0, 100.0);
    FAIL() << "no error";
  } catch (const OptionsError& e) {
    EXPECT_NE(std::string(e.what()).find("markings[0] and markings[1]"), std::string::npos)
        << e.what();
  }
  // Side by side in different lanes is fine.
  const ScenarioOptions ok =
      Load(Minimal("markings: [{class: diamond, s_m: 50, lanes: [0, 1, 2], length_m: 3}]\n"));
  EXPECT_EQ(SimWorld(ok, Classes(), 0.0, 100.0).markings().size(), 3u);
}

TEST(SimScenario, FileErrorsNameTheFile) {
  try {
    LoadScenarioFile("/nonexistent/scenario.yaml", Classes());
    FAIL() << "no error";
  } catch (const OptionsError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/scenario.yaml"), std::string::npos);
  }
}

}  // namespace
}  // namespace sim
}  // namespace ipm_road_mapper
