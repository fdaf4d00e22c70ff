// Well-formed but absurd masks (docs/architecture.md "Bad input"): what no real lane line or
// marking produces is dropped by the extraction and counted by reason, and no map element
// comes of it; a frame whose foreground is absurd as a whole gives no observation while its
// pose is still used.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "common/road_scene.h"
#include "ipm_road_mapper/core/frontend/instance_extraction.h"
#include "ipm_road_mapper/core/mapper/mapper.h"

namespace ipm_road_mapper {
namespace {

using test::FillGround;
using test::PoseAt;
using test::Rect;

// Mask values of config/classes.yaml: 1 lane_white_solid, 10 arrow_straight, 21 stop_line.
constexpr std::uint16_t kSolidLane = 1 * kInstanceIdFactor;
constexpr std::uint16_t kArrow = 10 * kInstanceIdFactor;
constexpr std::uint16_t kStopLine = 21 * kInstanceIdFactor;

ClassTable ShippedClasses() {
  return ClassTable::LoadFile(std::string(IRM_SOURCE_DIR) + "/config/classes.yaml");
}

// Every known (class, instance) value of the shipped table, class by class.
std::vector<std::uint16_t> KnownValues(const ClassTable& classes, std::size_t n) {
  std::vector<std::uint16_t> values;
  for (const auto& [id, info] : classes.classes()) {
    for (int index = 0; index < kInstanceIdFactor && values.size() < n; ++index) {
      values.push_back(static_cast<std::uint16_t>(id * kInstanceIdFactor + index));
    }
  }
  return values;
}

class AbsurdMasksTest : public ::testing::Test {
 protected:
  FrameObservations Extract(const cv::Mat& mask) const {
    return ExtractObservations(mask, classes_, ipm_, error_model_, options_);
  }

  // A mask with one ground rectangle (base_link) of `value`.
  static cv::Mat GroundMask(double x0, double x1, double y0, double y1, std::uint16_t value) {
    cv::Mat mask = EmptyMask();
    FillGround(Rect(x0, x1, y0, y1), PoseAt(0.0), value, &mask);
    return mask;
  }

  static cv::Mat EmptyMask() { return cv::Mat::zeros(720, 1280, CV_16UC1); }

  // Nothing extracted at all.
  static void ExpectNothing(const FrameObservations& obs) {
    EXPECT_TRUE(obs.markings.empty());
    EXPECT_TRUE(obs.lanes.empty());
  }

  ClassTable classes_ = ShippedClasses();
  Ipm ipm_{PinholeCamera(test::TestCamera()), test::TestExtrinsic(), 100.0};
  IpmErrorModel error_model_;
  ExtractionOptions options_;
};

TEST_F(AbsurdMasksTest, PlausibleMaskIsUntouched) {
  // A real line, an arrow and a stop line across three lanes: nothing implausible.
  cv::Mat mask = GroundMask(4.0, 30.0, 1.7, 1.85, kSolidLane + 1);
  FillGround(Rect(10.0, 15.0, -0.6, 0.6), PoseAt(0.0), kArrow + 1, &mask);
  FillGround(Rect(18.0, 18.4, -5.0, 5.0), PoseAt(0.0), kStopLine + 1, &mask);
  const FrameObservations obs = Extract(mask);
  EXPECT_EQ(obs.lanes.size(), 1u);
  EXPECT_EQ(obs.markings.size(), 2u);
  EXPECT_EQ(obs.counters.lane_runs_too_wide, 0u);
  EXPECT_EQ(obs.counters.dropped_oversized, 0u);
  EXPECT_EQ(obs.counters.frames_too_much_coverage + obs.counters.frames_too_many_instances, 0u);
}

TEST_F(AbsurdMasksTest, WholeImageLaneInstance) {
  const cv::Mat mask(720, 1280, CV_16UC1, cv::Scalar(kSolidLane + 1));
  const FrameObservations obs = Extract(mask);
  ExpectNothing(obs);
  EXPECT_EQ(obs.counters.frames_too_much_coverage, 1u);
  EXPECT_EQ(obs.counters.dropped_absurd_frame, 1u);
  // Without the frame check, the lane check drops it: every row's run is meters wide.
  options_.max_coverage = 1.0;
  const FrameObservations lane = Extract(mask);
  ExpectNothing(lane);
  EXPECT_EQ(lane.counters.dropped_wide_lane, 1u);
  EXPECT_GT(lane.counters.lane_runs_too_wide, 50u);
}

TEST_F(AbsurdMasksTest, LaneDoublingBackIsDropped) {
  // One instance running out along y = 1.8 m, turning at 30 m and coming back along y = 3.0 m
  // (a U): most rows cross it twice, and which arm is the line is unknown.
  cv::Mat mask = GroundMask(4.0, 30.0, 1.725, 1.875, kSolidLane + 1);
  FillGround(Rect(29.7, 30.0, 1.725, 3.075), PoseAt(0.0), kSolidLane + 1, &mask);
  FillGround(Rect(4.0, 30.0, 2.925, 3.075), PoseAt(0.0), kSolidLane + 1, &mask);
  const FrameObservations obs = Extract(mask);
  ExpectNothing(obs);
  EXPECT_EQ(obs.counters.dropped_doubled_lane, 1u);
  EXPECT_GT(obs.counters.lane_rows_doubled, 20u);
  // A short second arm (a fork's first meters): kept, its rows counted.
  cv::Mat fork = GroundMask(4.0, 30.0, 1.725, 1.875, kSolidLane + 1);
  FillGround(Rect(27.0, 30.0, 2.1, 2.25), PoseAt(0.0), kSolidLane + 1, &fork);
  const FrameObservations kept = Extract(fork);
  ASSERT_EQ(kept.lanes.size(), 1u);
  EXPECT_EQ(kept.counters.dropped_doubled_lane, 0u);
  EXPECT_GT(kept.counters.lane_rows_doubled, 0u);
  // A plain line has no doubled row.
  EXPECT_EQ(Extract(GroundMask(4.0, 30.0, 1.725, 1.875, kSolidLane + 1)).counters.lane_rows_doubled,
            0u);
}

TEST_F(AbsurdMasksTest, LaneCoveringHalfTheImage) {
  // The left half of the image as one lane instance: under the frame's coverage bound, but
  // every row's run is meters wide on the ground.
  cv::Mat mask = EmptyMask();
  mask(cv::Rect(0, 0, 640, 720)).setTo(cv::Scalar(kSolidLane + 1));
  const FrameObservations obs = Extract(mask);
  ExpectNothing(obs);
  EXPECT_EQ(obs.counters.frames_too_much_coverage, 0u);
  EXPECT_EQ(obs.counters.dropped_wide_lane, 1u);
}

TEST_F(AbsurdMasksTest, WholeImageMarking) {
  const cv::Mat mask(720, 1280, CV_16UC1, cv::Scalar(kArrow + 1));
  const FrameObservations obs = Extract(mask);
  ExpectNothing(obs);
  // Cut by the border on every side and by the horizon: no observation, counted once (its
  // part below the horizon is centred beyond the marking range).
  EXPECT_EQ(
      obs.counters.dropped_range + obs.counters.dropped_oversized + obs.counters.dropped_border,
      1u);
}

TEST_F(AbsurdMasksTest, MarkingCoveringMostOfTheRoadDropsTheFrame) {
  // Inside the image (no border contact) but painting most of the road.
  cv::Mat mask = EmptyMask();
  mask(cv::Rect(5, 300, 1270, 415)).setTo(kArrow + 1);
  mask(cv::Rect(600, 500, 20, 20)).setTo(kArrow + 2);
  const FrameObservations obs = Extract(mask);
  ExpectNothing(obs);
  EXPECT_EQ(obs.counters.frames_too_much_coverage, 1u);
  EXPECT_EQ(obs.counters.dropped_absurd_frame, 2u);
}

TEST_F(AbsurdMasksTest, WideLaneBlob) {
  // A "lane" 3 m wide: every run is 2.4 m wider than a line.
  const FrameObservations obs = Extract(GroundMask(5.0, 30.0, -1.5, 1.5, kSolidLane + 1));
  ExpectNothing(obs);
  EXPECT_EQ(obs.counters.dropped_wide_lane, 1u);
  EXPECT_GT(obs.counters.lane_runs_too_wide, 20u);
  EXPECT_EQ(obs.counters.frames_too_much_coverage, 0u);
}

TEST_F(AbsurdMasksTest, WideRunsOfAPlausibleLaneGiveNoPoints) {
  // A real line whose near part the network smeared over 2 m: those runs give no point,
  // the line survives.
  cv::Mat mask = GroundMask(4.0, 30.0, 1.7, 1.85, kSolidLane + 1);
  FillGround(Rect(4.0, 5.5, 0.8, 2.8), PoseAt(0.0), kSolidLane + 1, &mask);
  const FrameObservations obs = Extract(mask);
  ASSERT_EQ(obs.lanes.size(), 1u);
  EXPECT_GT(obs.counters.lane_runs_too_wide, 0u);
  for (const LanePoint& p : obs.lanes[0].points) EXPECT_NEAR(p.p_base.y(), 1.775, 0.1);
}

TEST_F(AbsurdMasksTest, OversizedMarkings) {
  // An arrow 14 m long (the class allows 10) and one 5 m wide (4): both oversized.
  cv::Mat mask = GroundMask(6.0, 20.0, -0.6, 0.6, kArrow + 1);
  FillGround(Rect(12.0, 16.0, 1.0, 6.0), PoseAt(0.0), kArrow + 2, &mask);
  const FrameObservations obs = Extract(mask);
  ExpectNothing(obs);
  EXPECT_EQ(obs.counters.dropped_oversized, 2u);
  // The same 14 m as a stop line across the road: within its class's 20 m.
  const FrameObservations stop_line = Extract(GroundMask(15.0, 15.4, -7.0, 7.0, kStopLine + 1));
  EXPECT_EQ(stop_line.markings.size(), 1u);
  EXPECT_EQ(stop_line.counters.dropped_oversized, 0u);
}

TEST_F(AbsurdMasksTest, OnePixelSlivers) {
  // A lane one row high across the image: its only run is meters wide.
  cv::Mat lane_mask = EmptyMask();
  lane_mask.row(560).setTo(kSolidLane + 1);
  const FrameObservations lane = Extract(lane_mask);
  ExpectNothing(lane);
  EXPECT_EQ(lane.counters.dropped_wide_lane, 1u);
  // A marking one column wide down the road: no area on the ground.
  cv::Mat marking_mask = EmptyMask();
  marking_mask(cv::Rect(640, 420, 1, 290)).setTo(kArrow + 1);
  const FrameObservations marking = Extract(marking_mask);
  ExpectNothing(marking);
  EXPECT_EQ(marking.counters.dropped_degenerate, 1u);
}

TEST_F(AbsurdMasksTest, OutlineLeavingTheImageOnThreeSides) {
  // The bottom 160 rows, cut by the left, right and bottom sides.
  cv::Mat lane_mask = EmptyMask();
  lane_mask(cv::Rect(0, 560, 1280, 160)).setTo(kSolidLane + 1);
  const FrameObservations lane = Extract(lane_mask);
  ExpectNothing(lane);
  EXPECT_EQ(lane.counters.dropped_wide_lane, 1u);  // cut runs are at least this wide
  EXPECT_EQ(lane.counters.frames_too_much_coverage, 0u);
  cv::Mat marking_mask = EmptyMask();
  marking_mask(cv::Rect(0, 560, 1280, 160)).setTo(kArrow + 1);
  const FrameObservations marking = Extract(marking_mask);
  ExpectNothing(marking);
  EXPECT_EQ(marking.counters.dropped_border, 1u);
}

// `n` square instances of `side` px (the values of `values`) in a grid below the horizon,
// 2 px apart, away from the image border.
cv::Mat GridOfInstances(const std::vector<std::uint16_t>& values, int side) {
  cv::Mat mask = cv::Mat::zeros(720, 1280, CV_16UC1);
  const int pitch = side + 2, per_row = (1280 - 20) / pitch;
  for (std::size_t i = 0; i < values.size(); ++i) {
    const int col = 10 + static_cast<int>(i % per_row) * pitch;
    const int row = 400 + static_cast<int>(i / per_row) * pitch;
    mask(cv::Rect(col, row, side, side)).setTo(values[i]);
  }
  return mask;
}

TEST_F(AbsurdMasksTest, SixHundredPlausibleInstances) {
  // 600 arrow-sized blobs (14x14 px = 196 px, above the 150 px minimum).
  std::vector<std::uint16_t> values;
  for (int i = 0; i < 600; ++i) values.push_back(static_cast<std::uint16_t>(kArrow + i));
  const FrameObservations obs = Extract(GridOfInstances(values, 14));
  ExpectNothing(obs);
  EXPECT_EQ(obs.counters.instances_seen, 600u);
  EXPECT_EQ(obs.counters.frames_too_many_instances, 1u);
  EXPECT_EQ(obs.counters.dropped_absurd_frame, 600u);
  EXPECT_EQ(obs.counters.dropped_instance_limit, 0u);
}

TEST_F(AbsurdMasksTest, TenThousandTinyInstances) {
  const std::vector<std::uint16_t> values = KnownValues(classes_, 10000);
  ASSERT_EQ(values.size(), 10000u);
  const cv::Mat mask = GridOfInstances(values, 2);
  const FrameObservations obs = Extract(mask);
  ExpectNothing(obs);
  EXPECT_EQ(obs.counters.dropped_tiny, 10000u);
  // Were they large enough to pass the size minimum, there would still be far too many.
  options_.min_marking_pixels = options_.min_lane_pixels = 4;
  const FrameObservations candidates = Extract(mask);
  ExpectNothing(candidates);
  EXPECT_EQ(candidates.counters.frames_too_many_instances, 1u);
  EXPECT_EQ(candidates.counters.dropped_absurd_frame, 10000u);
}

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
