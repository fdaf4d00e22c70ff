// Tests of the inverse perspective mapping: round trips through the projection, the
// homography, the horizon and range rejections, and axis conventions (base_link x forward,
// y left, z up; optical frame x right, y down, z forward).
#include <gtest/gtest.h>

#include <cmath>
#include <ostream>
#include <string>

#include "common/test_scene.h"
#include "ipm_road_mapper/core/geometry/ipm.h"
#include "ipm_road_mapper/core/geometry/rigid_transform.h"

namespace ipm_road_mapper {
namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr double kCameraHeight = 1.5;
constexpr double kCameraAhead = 1.2;    // camera x in base_link
constexpr double kCameraLateral = 0.1;  // camera y in base_link

// True when the point is in front of the camera within normalized radius 1 (45 deg off
// axis). The plumb_bob polynomial of the distorted cameras here folds back beyond a radius of
// about 1.45; points past the fold project into the image but are not seen by a real lens.
bool WithinLensFov(const Ipm& ipm, const Eigen::Vector3d& p_base) {
  const Eigen::Vector3d p_cam = ipm.T_base_cam().inverse() * p_base;
  return p_cam.z() > 0.0 && p_cam.head<2>().norm() < p_cam.z();
}

// A camera kCameraHeight above the ground, pitched down by `pitch` (rad), with roll/yaw.
Eigen::Isometry3d MakeTBaseCam(double roll, double pitch, double yaw) {
  return test::MountedCamera(roll, pitch, yaw,
                             Eigen::Vector3d(kCameraAhead, kCameraLateral, kCameraHeight));
}

struct IpmCase {
  std::string name;
  bool distorted;
  double roll, pitch, yaw;
};

void PrintTo(const IpmCase& c, std::ostream* os) { *os << c.name; }

class IpmRoundTrip : public ::testing::TestWithParam<IpmCase> {
 protected:
  Ipm MakeIpm(double max_range_m = 1000.0) const {
    const IpmCase& c = GetParam();
    return Ipm(PinholeCamera(test::AsymmetricIntrinsics(c.distorted)),
               MakeTBaseCam(c.roll, c.pitch, c.yaw), max_range_m);
  }
};

TEST_P(IpmRoundTrip, GroundPointProjectedThenIpmedIsRecovered) {
  const Ipm ipm = MakeIpm();
  int tested = 0;
  for (double x = 3.0; x <= 40.0; x += 1.5) {
    for (double y = -8.0; y <= 8.0; y += 0.8) {
      const Eigen::Vector3d ground(x, y, 0.0);
      Eigen::Vector2d uv;
      ASSERT_TRUE(ipm.BaseToPixel(ground, &uv));
      if (!WithinLensFov(ipm, ground) || !ipm.camera().InImage(uv)) continue;
      ++tested;
      Eigen::Vector3d p;
      ASSERT_EQ(ipm.PixelToGround(uv, &p), IpmStatus::kOk) << "ground " << ground.transpose();
      EXPECT_LT((p - ground).norm(), 1e-9) << "ground " << ground.transpose() << " uv "
                                           << uv.transpose() << " ipm " << p.transpose();
    }
  }
  EXPECT_GT(tested, 200);
}

TEST_P(IpmRoundTrip, PixelToGroundThenBaseToPixelIsIdentity) {
  const Ipm ipm = MakeIpm();
  int tested = 0;
  for (double u = 0.0; u < 1280.0; u += 79.0) {
    for (double v = 719.0; v > 0.0; v -= 23.0) {
      Eigen::Vector3d p;
      if (ipm.PixelToGround({u, v}, &p) != IpmStatus::kOk) continue;
      ++tested;
      EXPECT_NEAR(p.z(), 0.0, 1e-12);
      Eigen::Vector2d uv;
      ASSERT_TRUE(ipm.BaseToPixel(p, &uv));
      EXPECT_LT((uv - Eigen::Vector2d(u, v)).norm(), 1e-6) << "pixel " << u << ", " << v;
    }
  }
  EXPECT_GT(tested, 200);
}

TEST_P(IpmRoundTrip, HomographyMapsGroundToUndistortedPixel) {
  const Ipm ipm = MakeIpm();
  const Eigen::Matrix3d H = ipm.HomographyGroundToImage();
  const Eigen::Matrix3d H_inv = ipm.HomographyImageToGround();
  EXPECT_LT((H_inv * H / (H_inv * H)(2, 2) - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  const Eigen::Matrix3d K = ipm.camera().K();
  for (double x = 4.0; x <= 30.0; x += 2.0) {
    for (double y = -5.0; y <= 5.0; y += 1.0) {
      if (!WithinLensFov(ipm, {x, y, 0.0})) continue;
      Eigen::Vector2d uv;
      ASSERT_TRUE(ipm.BaseToPixel({x, y, 0.0}, &uv));
      // The undistorted pixel of the full (distorted) projection.
      const Eigen::Vector2d xy = ipm.camera().UndistortToNormalized(uv);
      const Eigen::Vector3d uv_undistorted = K * Eigen::Vector3d(xy.x(), xy.y(), 1.0);
      const Eigen::Vector3d h = H * Eigen::Vector3d(x, y, 1.0);
      ASSERT_GT(h.z(), 0.0);
      EXPECT_LT((h.hnormalized() - uv_undistorted.hnormalized()).norm(), 1e-6)
          << "ground " << x << ", " << y;
      if (!GetParam().distorted) {
        EXPECT_LT((h.hnormalized() - uv).norm(), 1e-6) << "ground " << x << ", " << y;
      }
      const Eigen::Vector3d g = H_inv * uv_undistorted;
      EXPECT_LT((g.hnormalized() - Eigen::Vector2d(x, y)).norm(), 1e-9)
          << "ground " << x << ", " << y;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(
    Cameras, IpmRoundTrip,
    ::testing::Values(IpmCase{"Pitched", false, 0.0, 4.0 * kDeg, 0.0},
                      IpmCase{"PitchedDistorted", true, 0.0, 4.0 * kDeg, 0.0},
                      IpmCase{"RollYaw", false, 2.0 * kDeg, 3.0 * kDeg, -5.0 * kDeg},
                      IpmCase{"RollYawDistorted", true, -1.5 * kDeg, 5.0 * kDeg, 4.0 * kDeg}),
    [](const ::testing::TestParamInfo<IpmCase>& info) { return info.param.name; });

// Independent geometry: a camera h above the ground pitched down by theta sees the ground
// point d ahead of it on its centre column at v = cy + fy tan(atan(h / d) - theta).
TEST(Ipm, MatchesClosedFormForPitchedCamera) {
  const double pitch = 3.0 * kDeg;
  const CameraIntrinsics in = test::AsymmetricIntrinsics(false);
  Eigen::Isometry3d T_base_cam = MakeTBaseCam(0.0, pitch, 0.0);
  T_base_cam.translation().y() = 0.0;
  const Ipm ipm(PinholeCamera(in), T_base_cam, 1000.0);
  for (double d : {2.0, 5.0, 10.0, 25.0, 60.0}) {
    const double v = in.cy + in.fy * std::tan(std::atan(kCameraHeight / d) - pitch);
    Eigen::Vector3d p;
    ASSERT_EQ(ipm.PixelToGround({in.cx, v}, &p), IpmStatus::kOk) << d;
    EXPECT_NEAR(p.x(), kCameraAhead + d, 1e-9 * d * d);
    EXPECT_NEAR(p.y(), 0.0, 1e-9);
    EXPECT_NEAR(p.z(), 0.0, 1e-12);
  }
}

// Swapped axes or a flipped sign anywhere in the chain would break these.
TEST(Ipm, LeftIsLeftOfCentreAndFartherIsHigher) {
  for (bool distorted : {false, true}) {
    const Ipm ipm(PinholeCamera(test::AsymmetricIntrinsics(distorted)),
                  MakeTBaseCam(0.0, 4.0 * kDeg, 0.0), 100.0);
    const double cx = ipm.camera().intrinsics().cx;
    Eigen::Vector2d left, right, near, far;
    ASSERT_TRUE(ipm.BaseToPixel({10.0, kCameraLateral + 2.0, 0.0}, &left));
    ASSERT_TRUE(ipm.BaseToPixel({10.0, kCameraLateral - 2.0, 0.0}, &right));
    ASSERT_TRUE(ipm.BaseToPixel({10.0, kCameraLateral, 0.0}, &near));
    ASSERT_TRUE(ipm.BaseToPixel({20.0, kCameraLateral, 0.0}, &far));
    EXPECT_LT(left.x(), cx - 50.0) << "a point to the left (+y) must be left in the image";
    EXPECT_GT(right.x(), cx + 50.0);
    // On the optical axis' vertical plane; tangential distortion (p2 y^2) shifts it slightly.
    EXPECT_NEAR(near.x(), cx, distorted ? 0.1 : 1e-6);
    EXPECT_LT(far.y(), near.y() - 20.0) << "a point farther ahead must be higher in the image";
    EXPECT_GT(near.y(), ipm.camera().intrinsics().cy);  // the ground is below the centre

    // And back: a pixel left of centre maps to +y, a lower pixel to a nearer point.
    Eigen::Vector3d p_left, p_low, p_high;
    ASSERT_EQ(ipm.PixelToGround({cx - 200.0, 600.0}, &p_left), IpmStatus::kOk);
    EXPECT_GT(p_left.y(), kCameraLateral);
    ASSERT_EQ(ipm.PixelToGround({cx, 650.0}, &p_low), IpmStatus::kOk);
    ASSERT_EQ(ipm.PixelToGround({cx, 500.0}, &p_high), IpmStatus::kOk);
    EXPECT_LT(p_low.x(), p_high.x());
    EXPECT_GT(p_low.x(), kCameraAhead);  // in front of the camera, not behind
  }
}

TEST(Ipm, PixelsAtOrAboveTheHorizonAreRejected) {
  const double pitch = 4.0 * kDeg;
  const CameraIntrinsics in = test::AsymmetricIntrinsics(false);
  const Ipm ipm(PinholeCamera(in), MakeTBaseCam(0.0, pitch, 0.0), 1e6);
  const double horizon_v = in.cy - in.fy * std::tan(pitch);  // ~280.9
  const Eigen::Vector3d sentinel(7.0, 8.0, 9.0);
  for (double u : {0.0, in.cx, 1279.0}) {
    for (double v : {0.0, 100.0, horizon_v - 1.0, horizon_v - 0.01, horizon_v}) {
      Eigen::Vector3d p = sentinel;
      EXPECT_EQ(ipm.PixelToGround({u, v}, &p), IpmStatus::kAboveHorizon) << u << ", " << v;
      EXPECT_EQ(p, sentinel) << "output written for a rejected pixel";
    }
    Eigen::Vector3d p;
    EXPECT_EQ(ipm.PixelToGround({u, horizon_v + 1.0}, &p), IpmStatus::kOk) << u;
    EXPECT_GT(p.x(), 500.0);  // just below the horizon: very far ahead
  }
}

TEST(Ipm, GroundPointsBeyondMaxRangeFromBaseOriginAreRejected) {
  // The range is the horizontal distance from base_link's origin, not from the camera
  // (which is kCameraAhead in front of it).
  const Ipm ipm(PinholeCamera(test::AsymmetricIntrinsics(true)), MakeTBaseCam(0.0, 4.0 * kDeg, 0.0),
                40.0);
  struct Case {
    Eigen::Vector3d ground;
    IpmStatus expected;
  };
  const Case cases[] = {
      {{39.5, 0.0, 0.0}, IpmStatus::kOk},
      {{40.5, 0.0, 0.0}, IpmStatus::kBeyondRange},   // 39.3 m from the camera
      {{36.0, 10.0, 0.0}, IpmStatus::kOk},           // 37.4 m
      {{38.0, 13.0, 0.0}, IpmStatus::kBeyondRange},  // 40.2 m: lateral offset counts
  };
  for (const Case& c : cases) {
    Eigen::Vector2d uv;
    ASSERT_TRUE(ipm.BaseToPixel(c.ground, &uv));
    const Eigen::Vector3d sentinel(-1.0, -2.0, -3.0);
    Eigen::Vector3d p = sentinel;
    EXPECT_EQ(ipm.PixelToGround(uv, &p), c.expected) << c.ground.transpose();
    if (c.expected == IpmStatus::kOk) {
      EXPECT_LT((p - c.ground).norm(), 1e-9);
    } else {
      EXPECT_EQ(p, sentinel);
    }
  }
}

TEST(Ipm, BaseToPixelRejectsPointsBehindTheCamera) {
  const Ipm ipm(PinholeCamera(test::AsymmetricIntrinsics(false)),
                MakeTBaseCam(0.0, 4.0 * kDeg, 0.0), 40.0);
  Eigen::Vector2d uv;
  EXPECT_FALSE(ipm.BaseToPixel({-5.0, 0.0, 0.0}, &uv));
  EXPECT_FALSE(ipm.BaseToPixel({kCameraAhead, kCameraLateral, kCameraHeight}, &uv));
  EXPECT_TRUE(ipm.BaseToPixel({5.0, 0.0, 0.0}, &uv));
}

TEST(Ipm, AccessorsAndStatusNames) {
  const Eigen::Isometry3d T = MakeTBaseCam(0.01, 0.05, -0.02);
  const Ipm ipm(PinholeCamera(test::AsymmetricIntrinsics(true)), T, 33.0);
  EXPECT_TRUE(ipm.T_base_cam().isApprox(T, 0.0));
  EXPECT_EQ(ipm.max_range_m(), 33.0);
  EXPECT_EQ(ipm.camera().intrinsics().fx, 1000.0);
  EXPECT_STREQ(ToString(IpmStatus::kOk), "ok");
  EXPECT_STREQ(ToString(IpmStatus::kAboveHorizon), "above_horizon");
  EXPECT_STREQ(ToString(IpmStatus::kBeyondRange), "beyond_range");
}

}  // namespace
}  // namespace ipm_road_mapper
