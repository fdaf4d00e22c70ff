// Tests of the mapper options' loading (mapper_options.h): the `ipm` section, unknown keys,
// the shipped configs, and hostile configs (file errors, bounds that cannot work) whose
// errors name the file and the key. Other sections are tested with their modules.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "common/options_test_utils.h"
#include "ipm_road_mapper/core/frontend/class_table.h"
#include "ipm_road_mapper/core/io/yaml_options.h"
#include "ipm_road_mapper/core/mapper/mapper_options.h"

namespace ipm_road_mapper {
namespace {

// ---------------------------------------------------------------------------------------
// Mapper options (the `ipm` section; other sections are tested with their modules)
// ---------------------------------------------------------------------------------------

TEST(IpmOptions, DefaultsWhenSectionIsEmpty) {
  const IpmOptions o = LoadIpmOptions(ReaderOf("{}"));
  EXPECT_EQ(o.max_range_m, 40.0);
  EXPECT_EQ(o.error_model.pixel_error_px, Eigen::Vector2d(2.0, 2.0));
  EXPECT_NEAR(o.error_model.pitch_sigma_rad, 0.3 * kDeg, 1e-15);
  EXPECT_EQ(o.error_model.height_sigma_m, 0.05);
}

TEST(IpmOptions, ReadsValuesAndConvertsDegreesToRadians) {
  const IpmOptions o = LoadIpmOptions(
      ReaderOf("max_range_m: 25.5\npixel_error_px: [1.5, 3.0]\npitch_sigma_deg: 0.5\n"
               "height_sigma_m: 0.08"));
  EXPECT_EQ(o.max_range_m, 25.5);
  EXPECT_EQ(o.error_model.pixel_error_px, Eigen::Vector2d(1.5, 3.0));
  EXPECT_NEAR(o.error_model.pitch_sigma_rad, 0.5 * M_PI / 180.0, 1e-15);
  EXPECT_EQ(o.error_model.height_sigma_m, 0.08);
}

TEST(IpmOptions, InvalidValuesNameTheKey) {
  auto load = [](const std::string& yaml) { return [yaml] { LoadMapperOptions(ReaderOf(yaml)); }; };
  EXPECT_EQ(ErrorOf(load("ipm: {max_range_m: 0}")), "ipm.max_range_m: must be > 0 (got 0)");
  EXPECT_EQ(ErrorOf(load("ipm: {pitch_sigma_deg: -1}")),
            "ipm.pitch_sigma_deg: must be >= 0 (got -1)");
  EXPECT_EQ(ErrorOf(load("ipm: {height_sigma_m: -0.1}")),
            "ipm.height_sigma_m: must be >= 0 (got -0.1)");
  EXPECT_EQ(ErrorOf(load("ipm: {pixel_error_px: [1, 2, 3]}")),
            "ipm.pixel_error_px: must be [du, dv]");
  EXPECT_EQ(ErrorOf(load("ipm: {pixel_error_px: [1, .nan]}")),
            "ipm.pixel_error_px: must be finite");
  EXPECT_TRUE(StartsWith(ErrorOf(load("ipm: {max_range_m: far}")), "ipm.max_range_m: wrong type"));
  EXPECT_TRUE(
      StartsWith(ErrorOf(load("ipm: {pixel_error_px: 2}")), "ipm.pixel_error_px: wrong type"));
}

TEST(MapperOptions, UnknownKeysNameTheirPath) {
  EXPECT_EQ(ErrorOf([] { LoadMapperOptions(ReaderOf("ipm: {max_rang_m: 30}")); }),
            "ipm.max_rang_m: unknown key");
  EXPECT_EQ(ErrorOf([] { LoadMapperOptions(ReaderOf("ipmm: {max_range_m: 30}")); }),
            "ipmm: unknown key");
  EXPECT_EQ(ErrorOf([] { LoadMapperOptions(ReaderOf("ipm: 3")); }), "ipm: must be a map");
}

TEST(MapperOptions, IpmGroundIsBaseLinkByDefaultAndTrajectoryOnRequest) {
  EXPECT_EQ(MapperOptions().ipm.ground, IpmGround::kBaseLink);
  const MapperOptions o = LoadMapperOptions(
      ReaderOf("ipm: {ground: trajectory, road_grade_length_m: 20, road_cross_slope_window_s: 2}"));
  EXPECT_EQ(o.ipm.ground, IpmGround::kTrajectory);
  EXPECT_EQ(o.ipm.road_plane.grade_length_m, 20.0);
  EXPECT_EQ(o.ipm.road_plane.cross_slope_window_s, 2.0);
  EXPECT_NE(ToString(o).find("ipm.ground: trajectory\n"), std::string::npos);
  EXPECT_EQ(
      ErrorOf([] { LoadMapperOptions(ReaderOf("ipm: {ground: road}")); }).rfind("ipm.ground", 0),
      0u);
  EXPECT_FALSE(
      ErrorOf([] { LoadMapperOptions(ReaderOf("ipm: {road_grade_length_m: 0}")); }).empty());
}

TEST(MapperOptions, ShippedMapperYamlLoads) {
  const std::string path = kConfigDir + "/mapper.yaml";
  MapperOptions o;
  try {
    o = LoadMapperOptions(OptionsReader::FromFile(path));
  } catch (const OptionsError& e) {
    FAIL() << e.what();
  }
  // Compared with the file read independently (so editing the file does not break this).
  const YAML::Node ipm = YAML::LoadFile(path)["ipm"];
  ASSERT_TRUE(ipm.IsMap());
  if (ipm["max_range_m"]) {
    EXPECT_EQ(o.ipm.max_range_m, ipm["max_range_m"].as<double>());
  }
  if (ipm["pitch_sigma_deg"]) {
    EXPECT_NEAR(o.ipm.error_model.pitch_sigma_rad, ipm["pitch_sigma_deg"].as<double>() * kDeg,
                1e-15);
  }
  if (ipm["height_sigma_m"]) {
    EXPECT_EQ(o.ipm.error_model.height_sigma_m, ipm["height_sigma_m"].as<double>());
  }
  if (ipm["pixel_error_px"]) {
    const auto e = ipm["pixel_error_px"].as<std::vector<double>>();
    EXPECT_EQ(o.ipm.error_model.pixel_error_px, Eigen::Vector2d(e[0], e[1]));
  }
  // Sanity: the file's values are the docs/design.md §4 ones, in radians inside the code.
  EXPECT_GT(o.ipm.max_range_m, 0.0);
  EXPECT_LT(o.ipm.error_model.pitch_sigma_rad, 0.1);  // radians, not 0.3 "degrees"
  const std::string dump = ToString(o);
  EXPECT_NE(dump.find("ipm.max_range_m"), std::string::npos);
  EXPECT_NE(dump.find("ipm.pitch_sigma_deg"), std::string::npos);
}

TEST(MapperOptions, FileErrorsNameTheFileAndTheKey) {
  EXPECT_EQ(FileError("type_number", "ipm: {max_range_m: far}\n"),
            "ipm.max_range_m: wrong type: expected a number, got the scalar 'far'");
  EXPECT_EQ(FileError("type_map", "ipm: [1, 2]\n"), "ipm: must be a map");
  EXPECT_EQ(FileError("type_list", "backend: {translation_prior_sigma_m: {x: 1}}\n"),
            "backend.translation_prior_sigma_m: wrong type: expected a sequence of numbers, "
            "got a map");
  EXPECT_EQ(FileError("type_string", "input: {base_frame: [base_link]}\n"),
            "input.base_frame: wrong type: expected a string, got a sequence");
  EXPECT_EQ(FileError("chord", "lanes: {chord_spacing_m: 1e-4}\n"),
            "lanes.chord_spacing_m: must be >= 0.5 m (got 0.0001)");
}

TEST(IpmOptions, AllErrorSourcesZeroOrNegativePixelErrorsAreRejected) {
  auto load = [](const std::string& yaml) { return [yaml] { LoadMapperOptions(ReaderOf(yaml)); }; };
  EXPECT_EQ(
      ErrorOf(load("ipm: {pixel_error_px: [0, 0], pitch_sigma_deg: 0, height_sigma_m: 0}")),
      "ipm: pixel_error_px, pitch_sigma_deg and height_sigma_m are all 0: at least one must be "
      "> 0");
  EXPECT_EQ(ErrorOf(load("ipm: {pixel_error_px: [-1, 2]}")), "ipm.pixel_error_px: must be >= 0");
  EXPECT_EQ(ErrorOf(load("ipm: {pixel_error_px: [2, -0.5]}")), "ipm.pixel_error_px: must be >= 0");
  // One source is enough.
  for (const char* one : {"ipm: {pixel_error_px: [0, 0], pitch_sigma_deg: 0.1, height_sigma_m: 0}",
                          "ipm: {pixel_error_px: [0, 0], pitch_sigma_deg: 0, height_sigma_m: 0.1}",
                          "ipm: {pixel_error_px: [0, 1], pitch_sigma_deg: 0, height_sigma_m: 0}"}) {
    EXPECT_NO_THROW(LoadMapperOptions(ReaderOf(one))) << one;
  }
}

TEST(LaneOptions, ChordSpacingHasAFloor) {
  EXPECT_EQ(ErrorOf([] { LoadMapperOptions(ReaderOf("lanes: {chord_spacing_m: 0.49}")); }),
            "lanes.chord_spacing_m: must be >= 0.5 m (got 0.49)");
  EXPECT_EQ(ErrorOf([] { LoadMapperOptions(ReaderOf("lanes: {chord_spacing_m: .inf}")); }),
            "lanes.chord_spacing_m: must be >= 0.5 m (got inf)");
  const MapperOptions o = LoadMapperOptions(ReaderOf("lanes: {chord_spacing_m: 0.5}"));
  EXPECT_EQ(o.lanes.fit.chord_spacing_m, 0.5);
}

TEST(BackendOptions, SolvingLessOftenThanTheWindowIsRejected) {
  EXPECT_EQ(ErrorOf([] {
              LoadMapperOptions(ReaderOf("backend: {window_frames: 10, solve_every_n_frames: 20}"));
            }),
            "backend.solve_every_n_frames: must be <= window_frames (10), got 20");
  EXPECT_NO_THROW(
      LoadMapperOptions(ReaderOf("backend: {window_frames: 10, solve_every_n_frames: 10}")));
}

TEST(OptionLoaders, SizesAndProbabilitiesOutOfRangeNameTheKey) {
  auto error = [](const std::string& yaml) {
    return ErrorOf([yaml] { LoadMapperOptions(ReaderOf(yaml)); });
  };
  EXPECT_EQ(error("extraction: {lane_row_step: 0}"),
            "extraction.lane_row_step: must be > 0 (got 0)");
  EXPECT_EQ(error("extraction: {max_instances_per_frame: -1}"),
            "extraction.max_instances_per_frame: must be > 0 (got -1)");
  EXPECT_EQ(error("association: {lane_min_support: 1.5}"),
            "association.lane_min_support: must be in [0, 1] (got 1.5)");
  EXPECT_EQ(error("association: {marking_merge_overlap: -0.1}"),
            "association.marking_merge_overlap: must be in [0, 1] (got -0.1)");
  EXPECT_EQ(error("extraction: {min_lane_points: 1}"),
            "extraction.min_lane_points: must be >= 2 (got 1)");
  EXPECT_EQ(error("odometry: {buffer_size: 0}"), "odometry.buffer_size: must be > 0 (got 0)");
  EXPECT_EQ(error("backend: {window_frames: 0}"), "backend.window_frames: must be > 0 (got 0)");
  EXPECT_EQ(error("backend: {queue_size: 0}"), "backend.queue_size: must be > 0 (got 0)");
  EXPECT_EQ(error("lanes: {selected_points_per_frame: 0}"),
            "lanes.selected_points_per_frame: must be > 0 (got 0)");
}

TEST(MapperOptions, EveryShippedMapperConfigLoads) {
  std::vector<std::string> paths = {kConfigDir + "/mapper.yaml"};
  for (const auto& entry : std::filesystem::directory_iterator(kConfigDir + "/ablations")) {
    if (entry.path().extension() == ".yaml") paths.push_back(entry.path().string());
  }
  EXPECT_GE(paths.size(), 8u);  // mapper.yaml and the 7 ablations of the benchmark
  for (const std::string& path : paths) {
    try {
      LoadMapperOptionsFile(path);
    } catch (const OptionsError& e) {
      ADD_FAILURE() << e.what();
    }
  }
}

}  // namespace
}  // namespace ipm_road_mapper
