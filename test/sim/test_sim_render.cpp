// The synthetic-drive renderer: frustum clipping (no wrap-around from points behind the
// camera or far outside the field of view) against a per-pixel ray-casting reference.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "ipm_road_mapper/sim/renderer.h"
#include "ipm_road_mapper/sim/scenario.h"

namespace ipm_road_mapper {
namespace sim {
namespace {

// A camera with a strong barrel distortion that folds back just outside the image, the
// case where projecting unclipped points gives garbage.
PinholeCamera StrongDistortionCamera() {
  CameraIntrinsics in = DefaultIntrinsics();
  in.distortion = {{-0.2, 0.0, 0.0, 0.0, 0.0}};  // r_d = r - 0.2 r^3 peaks at r = 1.29
  return PinholeCamera(in);
}

// Reference rendering by ray casting: a pixel is set when its ray hits the plane y = h (the
// ground, 1.5 m below the optical center) inside the rectangle x in [x0, x1], z in [z0, z1]
// and within the depth limits.
cv::Mat RayCast(const PinholeCamera& camera, double h, double x0, double x1, double z0, double z1) {
  cv::Mat out = cv::Mat::zeros(camera.height(), camera.width(), CV_8UC1);
  for (int v = 0; v < camera.height(); ++v) {
    for (int u = 0; u < camera.width(); ++u) {
      const Eigen::Vector3d ray = camera.Unproject(Eigen::Vector2d(u, v));
      if (ray.y() <= 1e-9) continue;
      const Eigen::Vector3d p = ray * (h / ray.y());
      if (p.x() >= x0 && p.x() <= x1 && p.z() >= z0 && p.z() <= z1) out.at<uchar>(v, u) = 1;
    }
  }
  return out;
}

// Pixels where the two binary images differ, excluding a band of `band` px around the
// reference's boundary (edge pixels may go either way).
int InteriorMismatches(const cv::Mat& rendered, const cv::Mat& reference, int band) {
  int count = 0;
  for (int v = 0; v < reference.rows; ++v) {
    for (int u = 0; u < reference.cols; ++u) {
      if ((rendered.at<uchar>(v, u) != 0) == (reference.at<uchar>(v, u) != 0)) continue;
      bool near_edge = false;
      for (int dv = -band; dv <= band && !near_edge; ++dv) {
        for (int du = -band; du <= band && !near_edge; ++du) {
          const int uu = u + du, vv = v + dv;
          if (uu < 0 || vv < 0 || uu >= reference.cols || vv >= reference.rows) continue;
          near_edge = reference.at<uchar>(vv, uu) != reference.at<uchar>(v, u);
        }
      }
      if (!near_edge) ++count;
    }
  }
  return count;
}

TEST(SimRenderer, ClipPolygonKeepsTheFrontPartExactly) {
  // A unit square in the x-z plane from z = -1 to z = 1, clipped at z >= 0.5.
  const std::vector<Eigen::Vector3d> square = {{0, 0, -1}, {1, 0, -1}, {1, 0, 1}, {0, 0, 1}};
  const auto clipped = ClipPolygon(square, Eigen::Vector4d(0, 0, 1, -0.5));
  ASSERT_EQ(clipped.size(), 4u);
  double area = 0.0;
  for (std::size_t i = 0; i < clipped.size(); ++i) {
    EXPECT_GE(clipped[i].z(), 0.5 - 1e-12);
    const auto& a = clipped[i];
    const auto& b = clipped[(i + 1) % clipped.size()];
    area += a.x() * b.z() - b.x() * a.z();
  }
  EXPECT_NEAR(std::abs(area) / 2.0, 0.5, 1e-12);
  // Entirely behind: nothing; entirely in front: unchanged.
  EXPECT_TRUE(ClipPolygon(square, Eigen::Vector4d(0, 0, 1, -2.0)).empty());
  EXPECT_EQ(ClipPolygon(square, Eigen::Vector4d(0, 0, 1, 5.0)).size(), 4u);
}

TEST(SimRenderer, PixelCenterFillLabelsExactlyThePixelsWhoseCenterIsInside) {
  // An axis-aligned rectangle off the pixel grid: columns 11-30 and rows 21-40 have their
  // centers inside. cv::fillPoly (the default rule) labels columns 10-31 and rows 20-41: half
  // a pixel more on each side.
  const std::vector<Eigen::Vector2d> rectangle = {
      {10.3, 20.3}, {30.7, 20.3}, {30.7, 40.7}, {10.3, 40.7}};
  cv::Mat dilated = cv::Mat::zeros(64, 64, CV_16UC1);
  FillPixelPolygon(rectangle, 7, &dilated);
  EXPECT_EQ(cv::countNonZero(dilated), 22 * 22);
  cv::Mat image = cv::Mat::zeros(64, 64, CV_16UC1);
  const cv::Rect box = FillPixelPolygon(rectangle, 7, &image, FillRule::kPixelCenters);
  EXPECT_EQ(box, cv::Rect(11, 21, 20, 20));
  EXPECT_EQ(cv::countNonZero(image), 400);
  EXPECT_EQ(image.at<std::uint16_t>(21, 11), 7);
  EXPECT_EQ(image.at<std::uint16_t>(20, 11), 0);
  EXPECT_EQ(image.at<std::uint16_t>(21, 10), 0);
  EXPECT_EQ(image.at<std::uint16_t>(41, 30), 0);

  // A slanted triangle and a concave arrow-like polygon: every pixel against the point test.
  const std::vector<std::vector<Eigen::Vector2d>> polygons = {
      {{5.2, 5.3}, {50.6, 12.4}, {20.1, 55.8}},
      {{4.5, 30.2},
       {30.4, 4.1},
       {58.7, 30.6},
       {40.2, 30.5},
       {40.6, 59.3},
       {20.3, 59.7},
       {20.8, 30.1}}};
  for (const std::vector<Eigen::Vector2d>& polygon : polygons) {
    cv::Mat filled = cv::Mat::zeros(64, 64, CV_8UC1);
    FillPixelPolygon(polygon, 1, &filled, FillRule::kPixelCenters);
    int mismatches = 0, inside_count = 0;
    for (int v = 0; v < 64; ++v) {
      for (int u = 0; u < 64; ++u) {
        bool inside = false;  // even-odd ray test
        for (std::size_t i = 0, j = polygon.size() - 1; i < polygon.size(); j = i++) {
          const Eigen::Vector2d& a = polygon[i];
          const Eigen::Vector2d& b = polygon[j];
          if ((a.y() > v) != (b.y() > v) &&
              u < a.x() + (v - a.y()) * (b.x() - a.x()) / (b.y() - a.y())) {
            inside = !inside;
          }
        }
        inside_count += inside;
        mismatches += inside != (filled.at<std::uint8_t>(v, u) != 0);
      }
    }
    EXPECT_GT(inside_count, 500);
    EXPECT_EQ(mismatches, 0);
  }
  // Outside the image or not finite: nothing, and an empty box.
  cv::Mat untouched = cv::Mat::zeros(64, 64, CV_8UC1);
  for (const FillRule rule : {FillRule::kPixelCenters, FillRule::kOpenCvFillPoly}) {
    EXPECT_TRUE(
        FillPixelPolygon({{70.0, 1.0}, {90.0, 1.0}, {80.0, 20.0}}, 1, &untouched, rule).empty());
    EXPECT_TRUE(
        FillPixelPolygon({{1.0, 1.0}, {std::nan(""), 1.0}, {8.0, 20.0}}, 1, &untouched, rule)
            .empty());
  }
  EXPECT_EQ(cv::countNonZero(untouched), 0);
}

TEST(SimRenderer, PolygonStraddlingTheCameraPlaneRendersLikeRayCasting) {
  // A ground rectangle from 5 m behind the camera to 12 m ahead, 3 m wide.
  for (const PinholeCamera& camera :
       {PinholeCamera(DefaultIntrinsics()), StrongDistortionCamera()}) {
    const double h = 1.5, near = 0.2;
    const FrustumProjector projector(camera, near, 100.0);
    const std::vector<Eigen::Vector3d> quad = {
        {-1.5, h, -5.0}, {1.5, h, -5.0}, {1.5, h, 12.0}, {-1.5, h, 12.0}};
    cv::Mat rendered = cv::Mat::zeros(camera.height(), camera.width(), CV_8UC1);
    FillPixelPolygon(projector.Project(quad), 1, &rendered);
    const cv::Mat reference = RayCast(camera, h, -1.5, 1.5, near, 12.0);
    EXPECT_GT(cv::countNonZero(reference), 10000);
    EXPECT_EQ(InteriorMismatches(rendered, reference, 1), 0);
    // Nothing at all above the horizon row band (the garbage of unclipped projection lands
    // there).
    EXPECT_EQ(cv::countNonZero(rendered.rowRange(0, camera.height() / 2 - 10)), 0);
  }
}

TEST(SimRenderer, PolygonFarOutsideTheFieldOfViewDoesNotFoldBack) {
  // A 400 m wide ground band: its far sides lie where the distortion polynomial folds back.
  const PinholeCamera camera = StrongDistortionCamera();
  const double h = 1.5;
  const FrustumProjector projector(camera, 0.2, 100.0);
  const std::vector<Eigen::Vector3d> band = {
      {-200.0, h, 4.0}, {200.0, h, 4.0}, {200.0, h, 6.0}, {-200.0, h, 6.0}};
  cv::Mat rendered = cv::Mat::zeros(camera.height(), camera.width(), CV_8UC1);
  FillPixelPolygon(projector.Project(band), 1, &rendered);
  const cv::Mat reference = RayCast(camera, h, -200.0, 200.0, 4.0, 6.0);
  EXPECT_GT(cv::countNonZero(reference), 1000);
  EXPECT_EQ(InteriorMismatches(rendered, reference, 1), 0);
}

TEST(SimRenderer, NaiveProjectionOfTheSameBandWouldFoldBack) {
  // Guards the test above: a band point 62 deg off axis (outside the ~41 deg half field of
  // view) projects INSIDE the image when the distortion is evaluated unclipped.
  const PinholeCamera camera = StrongDistortionCamera();
  Eigen::Vector2d uv;
  ASSERT_TRUE(camera.Project<double>(Eigen::Vector3d(9.5, 1.5, 5.0), &uv));
  EXPECT_TRUE(camera.InImage(uv)) << uv.transpose();
}

TEST(SimRenderer, FarPlaneLimitsTheRange) {
  const PinholeCamera camera(DefaultIntrinsics());
  const FrustumProjector projector(camera, 0.2, 10.0);
  const std::vector<Eigen::Vector3d> quad = {
      {-1.0, 1.5, 5.0}, {1.0, 1.5, 5.0}, {1.0, 1.5, 30.0}, {-1.0, 1.5, 30.0}};
  cv::Mat rendered = cv::Mat::zeros(camera.height(), camera.width(), CV_8UC1);
  FillPixelPolygon(projector.Project(quad), 1, &rendered);
  EXPECT_EQ(InteriorMismatches(rendered, RayCast(camera, 1.5, -1.0, 1.0, 5.0, 10.0), 1), 0);
}

TEST(SimRenderer, JitterFieldIsSmoothAndBounded) {
  const JitterField field(1.0, 40.0, {{0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8}});
  double max_shift = 0.0;
  for (int u = 0; u < 1280; u += 7) {
    for (int v = 0; v < 720; v += 11) {
      const Eigen::Vector2d p(u, v);
      const Eigen::Vector2d d = field.Apply(p) - p;
      max_shift = std::max(max_shift, d.norm());
      // Neighbouring pixels move alike (no tearing between shared polygon edges).
      EXPECT_LT((field.Apply(p + Eigen::Vector2d(1, 0)) - p - Eigen::Vector2d(1, 0) - d).norm(),
                0.3);
    }
  }
  EXPECT_LE(max_shift, 2.0 + 1e-9);
  EXPECT_GT(max_shift, 0.5);
}

}  // namespace
}  // namespace sim
}  // namespace ipm_road_mapper
