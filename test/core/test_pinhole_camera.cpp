// Tests of the plumb_bob pinhole camera against OpenCV (the reference implementation of the
// model that sensor_msgs/CameraInfo describes) and of its autodiff through the undistortion.
#include <ceres/jet.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <vector>

#include "common/test_scene.h"
#include "ipm_road_mapper/core/geometry/pinhole_camera.h"

namespace ipm_road_mapper {
namespace {

cv::Mat CvCameraMatrix(const CameraIntrinsics& in) {
  return (cv::Mat_<double>(3, 3) << in.fx, 0.0, in.cx, 0.0, in.fy, in.cy, 0.0, 0.0, 1.0);
}

cv::Mat CvDistortion(const CameraIntrinsics& in) {
  cv::Mat d(1, 5, CV_64F);
  for (int i = 0; i < 5; ++i) d.at<double>(i) = in.distortion[i];
  return d;
}

// Points in front of the camera covering the image (normalized coords up to about the
// corners, where this distortion is still monotonic), at several depths.
std::vector<cv::Point3d> GridPoints() {
  std::vector<cv::Point3d> points;
  for (double depth : {0.5, 3.0, 40.0}) {
    for (double x = -0.7; x <= 0.7001; x += 0.1) {
      for (double y = -0.4; y <= 0.4001; y += 0.08) {
        points.emplace_back(x * depth, y * depth, depth);
      }
    }
  }
  return points;
}

// Pixels covering the whole image including its border.
std::vector<Eigen::Vector2d> GridPixels(const CameraIntrinsics& in) {
  std::vector<Eigen::Vector2d> pixels;
  for (double u = 0.0; u <= in.width - 1; u += (in.width - 1) / 16.0) {
    for (double v = 0.0; v <= in.height - 1; v += (in.height - 1) / 9.0) {
      pixels.emplace_back(u, v);
    }
  }
  return pixels;
}

class PinholeCameraVsOpenCv : public ::testing::TestWithParam<bool> {};

TEST_P(PinholeCameraVsOpenCv, ProjectMatchesProjectPoints) {
  const CameraIntrinsics in = test::AsymmetricIntrinsics(GetParam());
  const PinholeCamera camera(in);
  const std::vector<cv::Point3d> points = GridPoints();
  std::vector<cv::Point2d> expected;
  cv::projectPoints(points, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), CvCameraMatrix(in),
                    CvDistortion(in), expected);
  ASSERT_EQ(expected.size(), points.size());
  double max_error = 0.0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    Eigen::Vector2d uv;
    ASSERT_TRUE(camera.Project(Eigen::Vector3d(points[i].x, points[i].y, points[i].z), &uv));
    const double error = (uv - Eigen::Vector2d(expected[i].x, expected[i].y)).norm();
    max_error = std::max(max_error, error);
    EXPECT_LT(error, 1e-6) << "point " << points[i] << " uv " << uv.transpose() << " opencv "
                           << expected[i];
  }
  RecordProperty("max_error_px", std::to_string(max_error));
}

TEST_P(PinholeCameraVsOpenCv, UndistortMatchesUndistortPointsAndInvertsProject) {
  const CameraIntrinsics in = test::AsymmetricIntrinsics(GetParam());
  const PinholeCamera camera(in);
  const std::vector<Eigen::Vector2d> pixels = GridPixels(in);
  std::vector<cv::Point2d> cv_pixels;
  for (const auto& p : pixels) cv_pixels.emplace_back(p.x(), p.y());
  std::vector<cv::Point2d> expected;
  cv::undistortPoints(
      cv_pixels, expected, CvCameraMatrix(in), CvDistortion(in), cv::noArray(), cv::noArray(),
      cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 100, 1e-14));
  ASSERT_EQ(expected.size(), pixels.size());
  for (std::size_t i = 0; i < pixels.size(); ++i) {
    const Eigen::Vector2d xy = camera.UndistortToNormalized(pixels[i]);
    // Compared in pixels: normalized differences scaled by the focal lengths.
    EXPECT_NEAR(xy.x() * in.fx, expected[i].x * in.fx, 1e-6) << "pixel " << pixels[i].transpose();
    EXPECT_NEAR(xy.y() * in.fy, expected[i].y * in.fy, 1e-6) << "pixel " << pixels[i].transpose();

    const Eigen::Vector3d ray = camera.Unproject(pixels[i]);
    EXPECT_DOUBLE_EQ(ray.z(), 1.0);
    Eigen::Vector2d uv;
    ASSERT_TRUE(camera.Project(Eigen::Vector3d(5.0 * ray), &uv));
    EXPECT_LT((uv - pixels[i]).norm(), 1e-6) << "pixel " << pixels[i].transpose();
  }
}

INSTANTIATE_TEST_SUITE_P(DistortedAndUndistorted, PinholeCameraVsOpenCv,
                         ::testing::Values(true, false),
                         [](const ::testing::TestParamInfo<bool>& info) {
                           return info.param ? "PlumbBob" : "NoDistortion";
                         });

TEST(PinholeCamera, OpticalFrameAxes) {
  // Optical frame: x right, y down, z forward.
  const PinholeCamera camera(test::AsymmetricIntrinsics(false));
  Eigen::Vector2d uv;
  ASSERT_TRUE(camera.Project(Eigen::Vector3d(0.0, 0.0, 10.0), &uv));
  EXPECT_NEAR(uv.x(), 652.3, 1e-12);
  EXPECT_NEAR(uv.y(), 351.7, 1e-12);
  ASSERT_TRUE(camera.Project(Eigen::Vector3d(1.0, 0.0, 10.0), &uv));
  EXPECT_NEAR(uv.x(), 652.3 + 100.0, 1e-9);  // right of centre, scaled by fx
  EXPECT_NEAR(uv.y(), 351.7, 1e-9);
  ASSERT_TRUE(camera.Project(Eigen::Vector3d(0.0, 1.0, 10.0), &uv));
  EXPECT_NEAR(uv.x(), 652.3, 1e-9);
  EXPECT_NEAR(uv.y(), 351.7 + 101.25, 1e-9);  // below centre, scaled by fy
}

TEST(PinholeCamera, RejectsPointsBehindOrTooCloseToTheCamera) {
  const PinholeCamera camera(test::AsymmetricIntrinsics(true));
  const Eigen::Vector2d sentinel(-123.0, -456.0);
  for (double z : {-5.0, 0.0, 0.5 * PinholeCamera::kMinDepth}) {
    Eigen::Vector2d uv = sentinel;
    EXPECT_FALSE(camera.Project(Eigen::Vector3d(0.1, 0.1, z), &uv)) << "z " << z;
    EXPECT_EQ(uv, sentinel) << "output written for a rejected point, z " << z;
  }
  Eigen::Vector2d uv;
  EXPECT_TRUE(camera.Project(Eigen::Vector3d(0.0, 0.0, 2.0 * PinholeCamera::kMinDepth), &uv));
}

TEST(PinholeCamera, ValidateCatchesBadIntrinsics) {
  EXPECT_EQ(PinholeCamera(test::AsymmetricIntrinsics(true)).Validate(), "");
  struct Case {
    const char* what;
    void (*mutate)(CameraIntrinsics*);
  };
  const Case cases[] = {
      {"zero width", [](CameraIntrinsics* in) { in->width = 0; }},
      {"negative height", [](CameraIntrinsics* in) { in->height = -1; }},
      {"zero fx", [](CameraIntrinsics* in) { in->fx = 0.0; }},
      {"negative fy", [](CameraIntrinsics* in) { in->fy = -500.0; }},
      {"NaN fx", [](CameraIntrinsics* in) { in->fx = std::numeric_limits<double>::quiet_NaN(); }},
      {"inf fy", [](CameraIntrinsics* in) { in->fy = std::numeric_limits<double>::infinity(); }},
      {"NaN cx", [](CameraIntrinsics* in) { in->cx = std::numeric_limits<double>::quiet_NaN(); }},
      {"inf cy", [](CameraIntrinsics* in) { in->cy = -std::numeric_limits<double>::infinity(); }},
      {"NaN k1",
       [](CameraIntrinsics* in) { in->distortion[0] = std::numeric_limits<double>::quiet_NaN(); }},
      {"inf k3",
       [](CameraIntrinsics* in) { in->distortion[4] = std::numeric_limits<double>::infinity(); }},
  };
  for (const Case& c : cases) {
    CameraIntrinsics in = test::AsymmetricIntrinsics(true);
    c.mutate(&in);
    EXPECT_NE(PinholeCamera(in).Validate(), "") << c.what;
  }
}

TEST(PinholeCamera, KAndHasDistortionAndInImage) {
  const PinholeCamera camera(test::AsymmetricIntrinsics(false));
  Eigen::Matrix3d K_expected;
  K_expected << 1000.0, 0.0, 652.3, 0.0, 1012.5, 351.7, 0.0, 0.0, 1.0;
  EXPECT_EQ(camera.K(), K_expected);
  EXPECT_FALSE(camera.HasDistortion());
  CameraIntrinsics in = test::AsymmetricIntrinsics(false);
  in.distortion[3] = 1e-6;  // any single nonzero coefficient counts
  EXPECT_TRUE(PinholeCamera(in).HasDistortion());

  EXPECT_TRUE(camera.InImage({0.0, 0.0}));
  EXPECT_TRUE(camera.InImage({1279.0, 719.0}));
  EXPECT_FALSE(camera.InImage({1279.5, 100.0}));
  EXPECT_FALSE(camera.InImage({100.0, -0.1}));
  EXPECT_FALSE(camera.InImage({5.0, 100.0}, 10.0));
  EXPECT_TRUE(camera.InImage({10.0, 100.0}, 10.0));
}

// d UndistortToNormalized / d uv via ceres::Jet against central differences.
TEST(PinholeCamera, UndistortJetDerivativeMatchesCentralDifferences) {
  const PinholeCamera camera(test::AsymmetricIntrinsics(true));
  using Jet = ceres::Jet<double, 2>;
  for (const Eigen::Vector2d& uv :
       {Eigen::Vector2d(652.3, 351.7), Eigen::Vector2d(30.0, 20.0), Eigen::Vector2d(1200.0, 650.0),
        Eigen::Vector2d(900.0, 100.0), Eigen::Vector2d(200.0, 600.0)}) {
    const Eigen::Matrix<Jet, 2, 1> uv_jet(Jet(uv.x(), 0), Jet(uv.y(), 1));
    const Eigen::Matrix<Jet, 2, 1> xy = camera.UndistortToNormalized(uv_jet);
    Eigen::Matrix2d J_auto;
    J_auto << xy(0).v(0), xy(0).v(1), xy(1).v(0), xy(1).v(1);

    const double step = 1e-2;  // px; central differences are O(step^2)
    Eigen::Matrix2d J_num;
    for (int k = 0; k < 2; ++k) {
      Eigen::Vector2d delta = Eigen::Vector2d::Zero();
      delta(k) = step;
      J_num.col(k) = (camera.UndistortToNormalized(Eigen::Vector2d(uv + delta)) -
                      camera.UndistortToNormalized(Eigen::Vector2d(uv - delta))) /
                     (2.0 * step);
    }
    EXPECT_NEAR(xy(0).a, camera.UndistortToNormalized(uv).x(), 1e-15);
    EXPECT_NEAR(xy(1).a, camera.UndistortToNormalized(uv).y(), 1e-15);
    EXPECT_LT((J_auto - J_num).norm(), 1e-7 * J_num.norm())
        << "uv " << uv.transpose() << "\nautodiff\n"
        << J_auto << "\nnumeric\n"
        << J_num;
    // Independent check: the derivative of the undistortion is the inverse of the
    // derivative of the projection (numerically, at the undistorted point).
    const Eigen::Vector2d xy0 = camera.UndistortToNormalized(uv);
    Eigen::Matrix2d J_project;
    for (int k = 0; k < 2; ++k) {
      Eigen::Vector2d delta = Eigen::Vector2d::Zero();
      delta(k) = 1e-6;
      Eigen::Vector2d plus, minus;
      ASSERT_TRUE(
          camera.Project(Eigen::Vector3d(xy0.x() + delta.x(), xy0.y() + delta.y(), 1.0), &plus));
      ASSERT_TRUE(
          camera.Project(Eigen::Vector3d(xy0.x() - delta.x(), xy0.y() - delta.y(), 1.0), &minus));
      J_project.col(k) = (plus - minus) / 2e-6;
    }
    EXPECT_LT((J_auto * J_project - Eigen::Matrix2d::Identity()).norm(), 1e-6)
        << "uv " << uv.transpose();
  }
}

TEST(PinholeCamera, UndistortWithoutDistortionIsTheAffineInverse) {
  const PinholeCamera camera(test::AsymmetricIntrinsics(false));
  const Eigen::Vector2d xy = camera.UndistortToNormalized(Eigen::Vector2d(752.3, 250.45));
  EXPECT_NEAR(xy.x(), 0.1, 1e-15);
  EXPECT_NEAR(xy.y(), -0.1, 1e-15);
}

}  // namespace
}  // namespace ipm_road_mapper
