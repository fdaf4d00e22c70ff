// Absurd masks in the Mapper (docs/architecture.md "Bad input"): a frame whose foreground
// is absurd is used for its pose but adds no element, bad marking instances are counted and
// leave no element, a lane doubling back or covering half the image makes no duplicate; and
// the options of the checks are validated. The extraction's checks: test_absurd_masks.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "common/class_values.h"
#include "common/road_scene.h"
#include "ipm_road_mapper/core/frontend/instance_extraction.h"
#include "ipm_road_mapper/core/mapper/mapper.h"

namespace ipm_road_mapper {
namespace {

using test::FillGround;
using test::Rect;

// The front end alone, on the road scene of road_scene.h.
Mapper MakeMapper() {
  MapperOptions options;
  options.backend.enabled = false;
  return Mapper(options, test::TestClasses(), test::TestExtrinsic());
}

TEST(AbsurdFramesInTheMapper, FrameIsUsedForThePoseButAddsNoElement) {
  Mapper mapper = MakeMapper();
  // The road frame plus 600 plausible arrows: too many instances.
  FrameInput crowded = test::RoadFrame(100.0, 0.0);
  for (int i = 0; i < 600; ++i) {
    const int col = 10 + (i % 60) * 21, row = 420 + (i / 60) * 21;
    crowded.mask(cv::Rect(col, row, 16, 16)).setTo(cv::Scalar(10100 + i));
  }
  ASSERT_EQ(mapper.ProcessFrame(crowded), FrameStatus::kUsed);
  // The road frame with its lane painted over most of the road.
  FrameInput painted = test::RoadFrame(100.05, 0.5);
  painted.mask(cv::Rect(5, 320, 1270, 395)).setTo(cv::Scalar(2001));
  ASSERT_EQ(mapper.ProcessFrame(painted), FrameStatus::kUsed);
  EXPECT_TRUE(mapper.map().markings.empty());
  EXPECT_TRUE(mapper.map().lanes.empty());
  EXPECT_EQ(mapper.counters().frames_used, 2u);
  const ExtractionCounters& c = mapper.counters().extraction;
  EXPECT_EQ(c.frames_too_many_instances, 1u);
  EXPECT_EQ(c.frames_too_much_coverage, 1u);
  // Normal frames after them map as usual.
  for (int k = 2; k < 8; ++k) {
    ASSERT_EQ(mapper.ProcessFrame(test::RoadFrame(100.0 + 0.05 * k, 0.5 * k)), FrameStatus::kUsed);
  }
  EXPECT_EQ(mapper.map().markings.size(), 1u);
  EXPECT_EQ(mapper.map().lanes.size(), 1u);
}

TEST(AbsurdFramesInTheMapper, BadMarkingInstancesAreCountedAndLeaveTheMap) {
  // A mapped arrow, then frames each with one bad marking instance on top of the road:
  // the whole image, a 1-px sliver, a blob leaving the image on three sides, 10,000 tiny
  // instances. Each is counted by its reason; the map keeps its one arrow.
  Mapper mapper = MakeMapper();
  for (int k = 0; k < 6; ++k) mapper.ProcessFrame(test::RoadFrame(100.0 + 0.05 * k, 0.5 * k));
  ASSERT_EQ(mapper.ExportMap(ExportOptions()).markings.size(), 1u);
  const std::uint64_t id = mapper.ExportMap(ExportOptions()).markings[0].id;
  std::vector<FrameInput> bad;
  bad.push_back(test::RoadFrame(100.30, 3.0));
  bad.back().mask.setTo(cv::Scalar(10900));
  bad.push_back(test::RoadFrame(100.35, 3.5));
  bad.back().mask(cv::Rect(100, 400, 900, 1)).setTo(cv::Scalar(10901));
  bad.push_back(test::RoadFrame(100.40, 4.0));
  bad.back().mask(cv::Rect(0, 560, 1280, 160)).setTo(cv::Scalar(10902));
  // 10,000 one-pixel instances on an otherwise empty mask: every known value of the test
  // classes (tiny) and the rest of unknown classes.
  bad.push_back(test::RoadFrame(100.45, 4.5));
  bad.back().mask.setTo(cv::Scalar(0));
  std::vector<std::uint16_t> values = KnownValues(test::TestClasses(), 10000);
  const std::size_t known = values.size();
  for (std::size_t i = known; i < 10000; ++i)
    values.push_back(static_cast<std::uint16_t>(30000 + i));
  for (std::size_t i = 0; i < values.size(); ++i) {
    bad.back().mask.at<std::uint16_t>(380 + 2 * static_cast<int>(i / 400),
                                      2 + 3 * static_cast<int>(i % 400)) = values[i];
  }
  const ExtractionCounters before = mapper.counters().extraction;
  for (const FrameInput& frame : bad) ASSERT_EQ(mapper.ProcessFrame(frame), FrameStatus::kUsed);
  const ExtractionCounters& c = mapper.counters().extraction;
  EXPECT_GE(c.dropped_border + c.dropped_range + c.dropped_oversized -
                (before.dropped_border + before.dropped_range + before.dropped_oversized),
            2u);  // whole image, three sides
  EXPECT_GT(c.dropped_degenerate + c.dropped_tiny, before.dropped_degenerate + before.dropped_tiny);
  EXPECT_EQ(c.dropped_tiny - before.dropped_tiny, known);  // the tiny instances
  EXPECT_EQ(c.dropped_unknown_class - before.dropped_unknown_class, values.size() - known);
  // The exported map keeps its one arrow (a bad instance is at most a tentative element).
  const VectorMap exported = mapper.ExportMap(ExportOptions());
  ASSERT_EQ(exported.markings.size(), 1u);
  EXPECT_EQ(exported.markings[0].id, id);
}

TEST(AbsurdFramesInTheMapper, LaneDoublingBackOrCoveringHalfTheImageMakesNoDuplicate) {
  // The dashed line of the road frames, with (in every other frame) its instance continued
  // by an arm coming back 1.2 m beside it, or the left half of the image painted with it:
  // one lane, on the line, and both counted.
  Mapper mapper = MakeMapper();
  for (int k = 0; k < 30; ++k) {
    const double x = 0.5 * k;
    FrameInput in = test::RoadFrame(100.0 + 0.05 * k, x, false);
    if (k % 4 == 1) {
      FillGround(Rect(x + 4.0, x + 30.0, 2.925, 3.075), in.T_map_base_odom, 2001, &in.mask);
      FillGround(Rect(x + 29.7, x + 30.0, 1.725, 3.075), in.T_map_base_odom, 2001, &in.mask);
    } else if (k % 4 == 3) {
      in.mask(cv::Rect(0, 0, 640, 720)).setTo(cv::Scalar(2001));
    }
    ASSERT_EQ(mapper.ProcessFrame(in), FrameStatus::kUsed);
  }
  const ExtractionCounters& c = mapper.counters().extraction;
  EXPECT_GE(c.dropped_doubled_lane, 7u);
  EXPECT_GE(c.dropped_wide_lane, 7u);
  const VectorMap map = mapper.ExportMap(ExportOptions());
  ASSERT_EQ(map.lanes.size(), 1u);
  for (std::size_t i = 1; i + 1 < map.lanes[0].control_points_map.size(); ++i) {
    EXPECT_NEAR(map.lanes[0].control_points_map[i].y(), 1.8, 0.3);
  }
}

// The error message of loading `yaml` as the `extraction` section.
std::string ExtractionError(const std::string& yaml) {
  try {
    LoadExtractionOptions(OptionsReader(YAML::Load(yaml), "extraction"));
  } catch (const OptionsError& e) {
    return e.what();
  }
  return "";
}

TEST(AbsurdMaskOptions, FrameLimitsAreValidated) {
  EXPECT_EQ(ExtractionError("{}"), "");
  EXPECT_NE(ExtractionError("{max_coverage: 0}").find("extraction.max_coverage"),
            std::string::npos);
  EXPECT_NE(ExtractionError("{max_coverage: 1.5}").find("must be in (0, 1]"), std::string::npos);
  EXPECT_NE(ExtractionError("{max_plausible_instances: 0}").find("max_plausible_instances"),
            std::string::npos);
}

// The error message of loading a class table.
std::string ClassTableError(const std::string& yaml) {
  try {
    ClassTable::Load(OptionsReader(YAML::Load(yaml), ""));
  } catch (const OptionsError& e) {
    return e.what();
  }
  return "";
}

TEST(AbsurdMaskOptions, ClassSizeBounds) {
  const ClassTable shipped = ShippedClasses();
  EXPECT_DOUBLE_EQ(shipped.Find(1)->max_width_m, 0.6);
  EXPECT_DOUBLE_EQ(shipped.Find(10)->max_length_m, 10.0);
  const ClassTable defaults = ClassTable::Load(OptionsReader(YAML::Load(R"(
classes:
  - {id: 1, name: l, kind: lane}
  - {id: 2, name: m, kind: marking}
)"),
                                                             ""));
  EXPECT_DOUBLE_EQ(defaults.Find(1)->max_width_m, kDefaultLaneMaxWidthM);
  EXPECT_DOUBLE_EQ(defaults.Find(2)->max_length_m, kDefaultMarkingMaxLengthM);
  EXPECT_DOUBLE_EQ(defaults.Find(2)->max_width_m, kDefaultMarkingMaxWidthM);
  EXPECT_NE(ClassTableError("classes: [{id: 1, name: l, kind: lane, max_length_m: 3}]")
                .find("max_length_m is for markings"),
            std::string::npos);
  EXPECT_NE(ClassTableError("classes: [{id: 1, name: m, kind: marking, max_width_m: -1}]")
                .find("max_width_m"),
            std::string::npos);
  EXPECT_NE(
      ClassTableError("classes: [{id: 1, name: m, kind: marking, max_length_m: 2, max_width_m: "
                      "3}]")
          .find("max_width_m must be <= max_length_m"),
      std::string::npos);
}

}  // namespace
}  // namespace ipm_road_mapper
