// The estimate of a marking seen only in far views: on a road that rises ahead of the viewing
// frames, flat-ground IPM puts it meters too far; re-measured on the road plane the poses
// that passed it give, it lands where it is.
#include <gtest/gtest.h>

#include <cmath>

#include "common/test_scene.h"
#include "ipm_road_mapper/core/geometry/ipm.h"
#include "ipm_road_mapper/core/mapper/far_marking_estimate.h"

namespace ipm_road_mapper {
namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr double kGrade = 0.01;  // 1 % up from x = 10 m
constexpr double kFlatUntilM = 10.0;

double RoadHeight(double x) { return kGrade * std::max(0.0, x - kFlatUntilM); }

// base_link on the road at x: on the grade it is pitched nose up by the grade.
Eigen::Isometry3d PoseOnRoad(double x) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  if (x > kFlatUntilM) T.linear() = RotationFromRpy(0.0, -std::atan(kGrade), 0.0);
  T.translation() = Eigen::Vector3d(x, 0.0, RoadHeight(x));
  return T;
}

class FarMarkingEstimateTest : public ::testing::Test {
 protected:
  FarMarkingEstimateTest() : store_(6.0) {
    for (int i = 0; i <= 40; ++i) store_.AddFrame(100.0 + 0.1 * i, PoseOnRoad(i));
    // A 3 x 0.6 m marking 30-33 m along, 1-1.6 m left, on the grade.
    truth_ = {
        Eigen::Vector3d(30.0, 1.0, RoadHeight(30.0)), Eigen::Vector3d(33.0, 1.0, RoadHeight(33.0)),
        Eigen::Vector3d(33.0, 1.6, RoadHeight(33.0)), Eigen::Vector3d(30.0, 1.6, RoadHeight(30.0))};
    // Seen whole from the flat part, 26-33 m ahead of the camera (frames 0, 2 and 4).
    element_.far_only = true;
    for (std::size_t frame : {0u, 2u, 4u}) {
      MarkingMeasurement meas;
      meas.frame_index = frame;
      const Eigen::Isometry3d T_cam_map =
          (store_.frames()[frame].T_map_base * T_base_cam_).inverse();
      for (int c = 0; c < 4; ++c) {
        EXPECT_TRUE(camera_.Project(T_cam_map * truth_[c], &meas.corners_uv[c]));
      }
      element_.history.push_back(meas);
    }
    // Its front-end estimate: flat-ground IPM from frame 0.
    const Ipm flat(camera_, T_base_cam_, 100.0);
    for (int c = 0; c < 4; ++c) {
      Eigen::Vector3d p_base;
      EXPECT_EQ(flat.PixelToGround(element_.history[0].corners_uv[c], &p_base), IpmStatus::kOk);
      element_.corners_map[c] = store_.frames()[0].T_map_base * p_base;
    }
  }

  const PinholeCamera camera_{test::Intrinsics1280x720()};
  const Eigen::Isometry3d T_base_cam_ = test::MountedCamera(0.0, 5.0 * kDeg, 0.0);
  MapStore store_;
  std::array<Eigen::Vector3d, 4> truth_;
  MarkingElement element_;
};

TEST_F(FarMarkingEstimateTest, FarViewsOnTheRoadPlaneLandWhereTheMarkingIs) {
  // Flat IPM: 0.2 m of rise 30 m ahead of a camera 1.5 m high puts it meters too far.
  EXPECT_GT((element_.Center() - 0.25 * (truth_[0] + truth_[1] + truth_[2] + truth_[3])).norm(),
            2.0);
  const std::optional<std::array<Eigen::Vector3d, 4>> corners =
      FarOnlyEstimate(camera_, T_base_cam_, IpmErrorModel(), store_, element_);
  ASSERT_TRUE(corners.has_value());
  for (int c = 0; c < 4; ++c) {
    EXPECT_NEAR(((*corners)[c] - truth_[c]).norm(), 0.0, 0.02) << "corner " << c;
  }
}

TEST_F(FarMarkingEstimateTest, AheadOfEveryPoseTheRoadAheadIsThePlane) {
  // Only the frames on the flat part have been driven (x <= 4 m): the marking 30 m along is
  // ahead of every pose. The newest pose's own plane (flat) puts it meters too far; the road
  // ahead as the trajectory knows it (here the grade itself) puts it where it is.
  MapStore early(6.0);
  for (int i = 0; i <= 4; ++i) early.AddFrame(100.0 + 0.1 * i, PoseOnRoad(i));
  const RoadPlane ahead{Eigen::Vector3d(kFlatUntilM, 0.0, 0.0),
                        Eigen::Vector3d(-kGrade, 0.0, 1.0).normalized()};
  const std::optional<std::array<Eigen::Vector3d, 4>> on_newest =
      FarOnlyEstimate(camera_, T_base_cam_, IpmErrorModel(), early, element_);
  const std::optional<std::array<Eigen::Vector3d, 4>> on_ahead =
      FarOnlyEstimate(camera_, T_base_cam_, IpmErrorModel(), early, element_, &ahead);
  ASSERT_TRUE(on_newest.has_value());
  ASSERT_TRUE(on_ahead.has_value());
  for (int c = 0; c < 4; ++c) {
    EXPECT_GT(((*on_newest)[c] - truth_[c]).norm(), 2.0) << "corner " << c;
    EXPECT_NEAR(((*on_ahead)[c] - truth_[c]).norm(), 0.0, 0.02) << "corner " << c;
  }
}

TEST_F(FarMarkingEstimateTest, NoViewThatMapsGivesNoEstimate) {
  for (MarkingMeasurement& meas : element_.history) {
    meas.corners_uv[2] = Eigen::Vector2d(640.0, 0.0);  // above the horizon
  }
  EXPECT_FALSE(FarOnlyEstimate(camera_, T_base_cam_, IpmErrorModel(), store_, element_));
}

}  // namespace
}  // namespace ipm_road_mapper
