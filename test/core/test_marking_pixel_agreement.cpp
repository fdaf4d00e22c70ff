// PixelsAgree: whether one element's views saw another, judged in the image. A copy put
// meters short by flat IPM beyond a crest still agrees in its pixels; a different marking,
// or a view that is not whole, does not.
#include <gtest/gtest.h>

#include <vector>

#include "common/test_scene.h"
#include "ipm_road_mapper/core/mapper/marking_pixel_agreement.h"

namespace ipm_road_mapper {
namespace {

using namespace test;  // NOLINT: the scene's helpers

// A 1 m x 2 m marking on the z = 0 plane, its near edge x_m ahead of the map origin.
std::array<Eigen::Vector3d, 4> Rectangle(double x_m) {
  return {Eigen::Vector3d(x_m, -0.5, 0.0), Eigen::Vector3d(x_m + 2.0, -0.5, 0.0),
          Eigen::Vector3d(x_m + 2.0, 0.5, 0.0), Eigen::Vector3d(x_m, 0.5, 0.0)};
}

struct Scene {
  Scene() {
    frames.resize(1);
    frames[0].index = 0;
    frames[0].T_map_base = Eigen::Isometry3d::Identity();
    model.corners_map = Rectangle(20.0);
  }
  // An element with one view in frame 0 whose pixels are those of `seen_corners_map`, and
  // whose own map estimate is `estimate_map` (where flat IPM put it).
  MarkingElement Viewed(const std::array<Eigen::Vector3d, 4>& seen_corners_map,
                        const std::array<Eigen::Vector3d, 4>& estimate_map) const {
    MarkingElement e;
    e.corners_map = estimate_map;
    MarkingMeasurement m;
    m.frame_index = 0;
    for (int i = 0; i < 4; ++i) EXPECT_TRUE(ipm.BaseToPixel(seen_corners_map[i], &m.corners_uv[i]));
    e.history.push_back(m);
    return e;
  }
  const Ipm ipm{PinholeCamera(Intrinsics1280x720()), MountedCamera(0.0, 0.0, 0.0), 100.0};
  IpmErrorModel error_model;  // gate 3 x hypot(2.8 px, 1000 px x 0.3 deg) = 17.9 px
  std::vector<FrameRecord> frames;
  MarkingElement model;
};

TEST(PixelsAgree, CopyPutShortByFlatIpmAgreesWithTheMarkingItSaw) {
  Scene s;
  // The copy's view saw the model's pixels; its map estimate is 4 m short.
  const MarkingElement copy = s.Viewed(s.model.corners_map, Rectangle(16.0));
  EXPECT_TRUE(PixelsAgree(s.ipm, s.error_model, 3.0, s.frames, s.model, copy));
}

TEST(PixelsAgree, AnotherMarkingFartherAheadDoesNot) {
  Scene s;
  // A marking 10 m farther: its center 1.5 m x 1000 px / 21 m - / 31 m = 23 px higher.
  const MarkingElement other = s.Viewed(Rectangle(30.0), Rectangle(30.0));
  EXPECT_FALSE(PixelsAgree(s.ipm, s.error_model, 3.0, s.frames, s.model, other));
  // Nor one beside it (1.5 m to the side: 70 px).
  std::array<Eigen::Vector3d, 4> beside = Rectangle(20.0);
  for (Eigen::Vector3d& c : beside) c.y() += 1.5;
  EXPECT_FALSE(PixelsAgree(s.ipm, s.error_model, 3.0, s.frames, s.model, s.Viewed(beside, beside)));
}

TEST(PixelsAgree, OnlyWholeViewsCount) {
  Scene s;
  MarkingElement partial = s.Viewed(s.model.corners_map, Rectangle(16.0));
  partial.history[0].side_measured[1] = false;  // cut by the border: its corners are not all real
  EXPECT_FALSE(PixelsAgree(s.ipm, s.error_model, 3.0, s.frames, s.model, partial));
}

TEST(PixelsAgree, MedianOverTheNewestViewsIgnoresOneOutlier) {
  Scene s;
  MarkingElement copy = s.Viewed(s.model.corners_map, Rectangle(16.0));
  copy.history.push_back(copy.history[0]);
  MarkingMeasurement outlier = copy.history[0];
  for (Eigen::Vector2d& uv : outlier.corners_uv) uv.x() += 200.0;
  copy.history.push_back(outlier);
  EXPECT_TRUE(PixelsAgree(s.ipm, s.error_model, 3.0, s.frames, s.model, copy));
}

}  // namespace
}  // namespace ipm_road_mapper
