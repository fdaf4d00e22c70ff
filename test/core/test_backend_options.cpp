// Tests of the back-end options: the robust kernel enum and its parse, the tuning knobs
// that were file-scope constants (same defaults, validated), the options dump, and the
// shipped config/mapper.yaml's backend section.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <string>

#include "common/options_test_utils.h"
#include "ipm_road_mapper/core/backend/backend_options.h"
#include "ipm_road_mapper/core/io/yaml_options.h"

namespace ipm_road_mapper {
namespace {

const std::string kMapperYaml = std::string(IRM_SOURCE_DIR) + "/config/mapper.yaml";

BackendOptions LoadFrom(const std::string& yaml) {
  return LoadBackendOptions(OptionsReader(YAML::Load(yaml), "backend"));
}

TEST(RobustKernel, ParsesEveryConfigStringAndRoundTrips) {
  EXPECT_EQ(ParseRobustKernel("huber"), RobustKernel::kHuber);
  EXPECT_EQ(ParseRobustKernel("cauchy"), RobustKernel::kCauchy);
  EXPECT_EQ(ParseRobustKernel("none"), RobustKernel::kNone);
  for (RobustKernel kernel : {RobustKernel::kHuber, RobustKernel::kCauchy, RobustKernel::kNone}) {
    EXPECT_EQ(ParseRobustKernel(ToString(kernel)), kernel) << ToString(kernel);
  }
}

TEST(RobustKernel, RejectsOtherStrings) {
  EXPECT_FALSE(ParseRobustKernel("Huber"));
  EXPECT_FALSE(ParseRobustKernel("tukey"));
  EXPECT_FALSE(ParseRobustKernel(""));
}

TEST(BackendOptions, RobustKernelIsReadFromItsString) {
  EXPECT_EQ(LoadFrom("{}").robust_kernel, RobustKernel::kHuber);  // the default
  EXPECT_EQ(LoadFrom("{robust_kernel: huber}").robust_kernel, RobustKernel::kHuber);
  EXPECT_EQ(LoadFrom("{robust_kernel: cauchy}").robust_kernel, RobustKernel::kCauchy);
  EXPECT_EQ(LoadFrom("{robust_kernel: none}").robust_kernel, RobustKernel::kNone);
}

TEST(BackendOptions, BadRobustKernelIsAnOptionsErrorNamingTheKey) {
  EXPECT_EQ(ErrorOf([] { LoadFrom("{robust_kernel: tukey}"); }),
            "backend.robust_kernel: must be huber, cauchy or none");
  EXPECT_EQ(ErrorOf([] {
              LoadFrom("{robust_kernel: [huber]}");
            }).rfind("backend.robust_kernel: wrong type", 0),
            0u);
}

TEST(BackendOptions, TheGlobalSolveJointStepAndStartAreReadAndValidated) {
  const BackendOptions defaults = LoadFrom("{}");
  EXPECT_EQ(defaults.final_global_joint_iterations, 50);
  EXPECT_TRUE(defaults.final_global_from_mounting);
  EXPECT_EQ(LoadFrom("{final_global_joint_iterations: 0}").final_global_joint_iterations, 0);
  EXPECT_FALSE(LoadFrom("{final_global_from_mounting: false}").final_global_from_mounting);
  const std::string text = ToString(LoadFrom("{final_global_joint_iterations: 7}"));
  EXPECT_NE(text.find("backend.final_global_joint_iterations: 7\n"), std::string::npos);
  EXPECT_NE(text.find("backend.final_global_from_mounting: true\n"), std::string::npos);
  EXPECT_EQ(ErrorOf([] { LoadFrom("{final_global_joint_iterations: -1}"); }),
            "backend.final_global_joint_iterations: must be >= 0");
  EXPECT_EQ(ErrorOf([] {
              LoadFrom("{final_global_from_mounting: 3}");
            }).rfind("backend.final_global_from_mounting: wrong type", 0),
            0u);
}

TEST(BackendOptions, GatesKeepTheirFormerDefaults) {
  const BackendOptions o = LoadFrom("{}");
  EXPECT_EQ(o.max_lane_pixel_distance_m, 1.5);
  EXPECT_EQ(o.max_outside_image_px, 100.0);
  EXPECT_FALSE(o.lane_pixels_on_lane_surface);
  EXPECT_TRUE(LoadFrom("{lane_pixels_on_lane_surface: true}").lane_pixels_on_lane_surface);
  EXPECT_NE(ToString(LoadFrom("{lane_pixels_on_lane_surface: true}"))
                .find("backend.lane_pixels_on_lane_surface: true\n"),
            std::string::npos);
}

TEST(BackendOptions, GatesAreReadAndValidated) {
  const BackendOptions o = LoadFrom("{max_lane_pixel_distance_m: 0.8, max_outside_image_px: 0}");
  EXPECT_EQ(o.max_lane_pixel_distance_m, 0.8);
  EXPECT_EQ(o.max_outside_image_px, 0.0);
  EXPECT_EQ(ErrorOf([] {
              LoadFrom("{max_lane_pixel_distance_m: 0}");
            }).rfind("backend.max_lane_pixel_distance_m: ", 0),
            0u);
  EXPECT_EQ(ErrorOf([] {
              LoadFrom("{max_outside_image_px: -1}");
            }).rfind("backend.max_outside_image_px: ", 0),
            0u);
}

TEST(BackendOptions, ExtrinsicCalibrationOptionsAreReadAndValidated) {
  const BackendOptions o = LoadFrom(
      "{extrinsic_min_information_ratio: 2, extrinsic_prior_memory_markings: 0, "
      "extrinsic_holdout_every_n_frames: 5}");
  EXPECT_EQ(o.extrinsic_min_information_ratio, 2.0);
  EXPECT_EQ(o.extrinsic_prior_memory_markings, 0.0);  // a plain sum
  EXPECT_EQ(o.extrinsic_holdout_every_n_frames, 5);
  EXPECT_EQ(ErrorOf([] {
              LoadFrom("{extrinsic_holdout_every_n_frames: 1}");  // nothing left to fit
            }).rfind("backend.extrinsic_holdout_every_n_frames: ", 0),
            0u);
  EXPECT_EQ(ErrorOf([] {
              LoadFrom("{extrinsic_prior_memory_markings: 0.5}");
            }).rfind("backend.extrinsic_prior_memory_markings: ", 0),
            0u);
  EXPECT_EQ(ErrorOf([] {
              LoadFrom("{extrinsic_min_information_ratio: -1}");
            }).rfind("backend.extrinsic_min_information_ratio: ", 0),
            0u);
  EXPECT_NE(ToString(o).find("backend.extrinsic_holdout_every_n_frames: 5\n"), std::string::npos);
}

TEST(BackendOptions, RoadCrownOptionsAreReadAndValidatedAndOffByDefault) {
  EXPECT_EQ(BackendOptions().road_crown_slope_sigma, 0.0);  // the planar prior of every drive
  const BackendOptions o = LoadFrom("{road_crown_slope_sigma: 0.03, road_crown_lateral_m: 2.5}");
  EXPECT_EQ(o.road_crown_slope_sigma, 0.03);
  EXPECT_EQ(o.road_crown_lateral_m, 2.5);
  EXPECT_EQ(ErrorOf([] {
              LoadFrom("{road_crown_slope_sigma: -0.01}");
            }).rfind("backend.road_crown_slope_sigma: ", 0),
            0u);
  EXPECT_EQ(ErrorOf([] {
              LoadFrom("{road_crown_lateral_m: 0}");
            }).rfind("backend.road_crown_lateral_m: ", 0),
            0u);
  EXPECT_NE(ToString(o).find("backend.road_crown_slope_sigma: 0.03\n"), std::string::npos);
}

TEST(BackendOptions, DumpListsTheKernelAndTheGates) {
  BackendOptions o;
  o.robust_kernel = RobustKernel::kCauchy;
  o.max_lane_pixel_distance_m = 0.75;
  const std::string dump = ToString(o);
  EXPECT_NE(dump.find("backend.robust_kernel: cauchy\n"), std::string::npos) << dump;
  EXPECT_NE(dump.find("backend.max_lane_pixel_distance_m: 0.75\n"), std::string::npos) << dump;
  EXPECT_NE(dump.find("backend.max_outside_image_px: 100\n"), std::string::npos) << dump;
}

TEST(BackendOptions, RetiredInformationForgetsByDefault) {
  // A plain sum of the retired markings' information held the windows' lever arm wherever it
  // had wandered (10 km drive: lane APE 0.103 m; docs/backend.md, "The 10 km drive's lever
  // arm"): the default prior is a marginal of the recent markings.
  const BackendOptions defaults;
  EXPECT_GT(defaults.extrinsic_prior_memory_markings, 1.0);
  EXPECT_EQ(LoadFrom("{}").extrinsic_prior_memory_markings,
            defaults.extrinsic_prior_memory_markings);
}

TEST(BackendOptions, ShippedMapperYamlKeepsTheDefaults) {
  const YAML::Node backend = YAML::LoadFile(kMapperYaml)["backend"];
  ASSERT_TRUE(backend.IsMap());
  const BackendOptions o = LoadBackendOptions(OptionsReader(backend, "backend"));
  const BackendOptions defaults;
  EXPECT_EQ(o.robust_kernel, ParseRobustKernel(backend["robust_kernel"].as<std::string>()));
  EXPECT_EQ(o.max_lane_pixel_distance_m, defaults.max_lane_pixel_distance_m);
  EXPECT_EQ(o.max_outside_image_px, defaults.max_outside_image_px);
  EXPECT_EQ(o.lane_pixels_on_lane_surface, defaults.lane_pixels_on_lane_surface);
  EXPECT_EQ(o.extrinsic_min_information_ratio, defaults.extrinsic_min_information_ratio);
  EXPECT_EQ(o.extrinsic_prior_memory_markings, defaults.extrinsic_prior_memory_markings);
  EXPECT_EQ(o.extrinsic_holdout_every_n_frames, defaults.extrinsic_holdout_every_n_frames);
}

}  // namespace
}  // namespace ipm_road_mapper
