// The scene the instance-extraction tests share (test_instance_extraction,
// test_lane_extraction, test_extraction_bounds): the mask values of config/classes.yaml's
// classes, that table, timing helpers and the fixture that extracts a mask with the test
// camera's IPM (mask_test_utils.h).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "common/class_values.h"
#include "common/mask_test_utils.h"
#include "common/units.h"
#include "ipm_road_mapper/core/frontend/instance_extraction.h"

namespace ipm_road_mapper {

using test::EmptyMask;
using test::GroundRectangle;
using test::kTestHeight;
using test::kTestWidth;
using test::RenderGroundRectangle;
using test::RenderLaneStrip;
using test::TestIpm;

// Mask values of config/classes.yaml classes: 1 lane_white_solid, 2 lane_white_dashed,
// 10 arrow_straight, 21 stop_line; class 50 is not in the table.
constexpr std::uint16_t kSolidLane = 1 * kInstanceIdFactor;
constexpr std::uint16_t kDashedLane = 2 * kInstanceIdFactor;
constexpr std::uint16_t kArrow = 10 * kInstanceIdFactor;
constexpr std::uint16_t kStopLine = 21 * kInstanceIdFactor;
constexpr std::uint16_t kUnknownClass = 50 * kInstanceIdFactor;

// The shipped class table (class_values.h).
inline ClassTable TestClasses() { return ShippedClasses(); }

// Milliseconds since `start`.
inline double MsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

// Timing bounds hold for optimized builds only (NDEBUG, as CMake's Release sets); other
// builds print the time without asserting it.
inline void ExpectFasterThan(double ms, double limit_ms) {
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

}  // namespace ipm_road_mapper
