// Ground truth and masks agree: with the true pose and extrinsic and no segmentation noise,
// every marking's painted interior and every painted lane point project onto pixels of the
// right instance, and each marking instance is tightly bounded by its projected true
// rectangle.
#include <gtest/gtest.h>

#include <map>
#include <opencv2/imgproc.hpp>
#include <set>

#include "ipm_road_mapper/sim/drive_simulator.h"

namespace ipm_road_mapper {
namespace sim {
namespace {

const std::string kSource = IRM_SOURCE_DIR;

class SimGroundTruthTest : public ::testing::TestWithParam<const char*> {
 protected:
  void SetUp() override {
    classes_ = ClassTable::LoadFile(kSource + "/config/classes.yaml");
    scenario_ = LoadScenarioFile(kSource + "/config/scenarios/" + GetParam() + ".yaml", classes_);
    drive_ = std::make_unique<DriveSimulator>(scenario_, classes_, 7);
  }

  // The pixel of a surface point in frame k (true pose, true extrinsic), when it is visible,
  // in the image with a margin and well inside the mask's depth range.
  bool PixelOf(int k, const SightProfile& sight, const SurfaceVertex& v,
               Eigen::Vector2d* uv) const {
    if (!sight.Visible(v.s, v.l, v.p_map.z())) return false;
    const Eigen::Isometry3d T_cam_map =
        (drive_->frame(k).T_map_base_true * drive_->T_base_cam_true()).inverse();
    const Eigen::Vector3d p_cam = T_cam_map * v.p_map;
    if (p_cam.z() < 1.0 || p_cam.z() > scenario_.segmentation.range_m - 1.0) return false;
    return drive_->camera().Project<double>(p_cam, uv) && drive_->camera().InImage(*uv, 3.0);
  }

  // True when the mask holds `value` at uv or at one of its 8 neighbours.
  static bool NearValue(const cv::Mat& mask, const Eigen::Vector2d& uv, int value) {
    const int u = static_cast<int>(std::lround(uv.x())), v = static_cast<int>(std::lround(uv.y()));
    for (int dv = -1; dv <= 1; ++dv) {
      for (int du = -1; du <= 1; ++du) {
        if (mask.at<std::uint16_t>(v + dv, u + du) == value) return true;
      }
    }
    return false;
  }

  ClassTable classes_;
  ScenarioOptions scenario_;
  std::unique_ptr<DriveSimulator> drive_;
};

TEST_P(SimGroundTruthTest, MasksAgreeWithTheGroundTruthGeometry) {
  RenderSettings exact;
  exact.segmentation_noise = false;
  exact.image = false;
  exact.record_visibility = false;
  const SimWorld& world = drive_->world();
  int checked_interior = 0, wrong_interior = 0, checked_lane = 0, wrong_lane = 0;
  int checked_rects = 0;
  for (int k = 0; k < drive_->num_frames(); k += 37) {
    const SimFrame frame = drive_->RenderFrame(k, exact);
    const SightProfile sight = drive_->CameraSight(k);
    std::set<int> values;
    std::map<int, int> lane_value;  // lane line id -> instance value
    for (const RenderedInstance& instance : frame.instances) {
      EXPECT_TRUE(values.insert(instance.value).second) << "duplicate instance " << instance.value;
      EXPECT_GT(instance.value % kInstanceIdFactor, 0);
      EXPECT_NE(instance.source, RenderedInstance::Source::kSpurious);
      if (instance.source == RenderedInstance::Source::kLane) {
        EXPECT_TRUE(lane_value.emplace(instance.gt_id, instance.value).second);
        EXPECT_EQ(instance.value / kInstanceIdFactor,
                  world.lane_lines()[instance.gt_id - 1].class_id);
        continue;
      }
      const SimMarking& m = world.markings()[instance.gt_id - 1];
      EXPECT_EQ(instance.value / kInstanceIdFactor, m.class_id);
      // Interior points of each convex component: its centroid and points halfway to its
      // vertices.
      for (const auto& component : m.shape_uw) {
        Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
        for (const auto& q : component) centroid += q / component.size();
        std::vector<Eigen::Vector2d> samples = {centroid};
        for (const auto& q : component) samples.push_back(0.5 * (centroid + q));
        for (const Eigen::Vector2d& uw : samples) {
          Eigen::Vector2d uv;
          if (!PixelOf(k, sight, world.MarkingPoint(m, uw), &uv)) continue;
          ++checked_interior;
          if (!NearValue(frame.mask, uv, instance.value)) ++wrong_interior;
        }
      }
      // Tightness: when the whole rectangle is in view, every instance pixel lies inside the
      // projected rectangle and each of its four sides touches the instance (within 1.5 px).
      std::vector<std::vector<cv::Point2f>> sides(4);
      bool whole = true;
      for (int side = 0; side < 4 && whole; ++side) {
        for (int i = 0; i <= 20 && whole; ++i) {
          const Eigen::Vector2d uw =
              m.rect_uw[side] + (m.rect_uw[(side + 1) % 4] - m.rect_uw[side]) * (i / 20.0);
          Eigen::Vector2d uv;
          whole = PixelOf(k, sight, world.MarkingPoint(m, uw), &uv);
          sides[side].emplace_back(uv.x(), uv.y());
        }
      }
      if (!whole) continue;
      ++checked_rects;
      std::vector<cv::Point2f> outline;
      for (const auto& side : sides) outline.insert(outline.end(), side.begin(), side.end() - 1);
      std::vector<double> side_distance(4, 1e9);
      for (int v = 0; v < frame.mask.rows; ++v) {
        for (int u = 0; u < frame.mask.cols; ++u) {
          if (frame.mask.at<std::uint16_t>(v, u) != instance.value) continue;
          const cv::Point2f p(u, v);
          ASSERT_GE(cv::pointPolygonTest(outline, p, true), -1.5)
              << m.class_name << " " << m.id << " frame " << k << " pixel " << u << "," << v;
          for (int side = 0; side < 4; ++side) {
            for (std::size_t i = 0; i + 1 < sides[side].size(); ++i) {
              const cv::Point2f a = sides[side][i], b = sides[side][i + 1];
              const cv::Point2f d = b - a;
              const float t = std::clamp((p - a).dot(d) / d.dot(d), 0.0f, 1.0f);
              side_distance[side] =
                  std::min<double>(side_distance[side], cv::norm(p - (a + t * d)));
            }
          }
        }
      }
      for (int side = 0; side < 4; ++side) {
        EXPECT_LE(side_distance[side], 1.5)
            << m.class_name << " " << m.id << " frame " << k << " side " << side;
      }
    }
    // Painted lane points land on their line's single instance.
    for (const SimLaneLine& line : world.lane_lines()) {
      for (double s = 0.0; s < world.road().length(); s += 0.5) {
        if (!line.IsPainted(s, 0.1)) continue;
        const SurfaceVertex v{world.road().SurfacePoint(s, line.offset_m), s, line.offset_m};
        Eigen::Vector2d uv;
        if (!PixelOf(k, sight, v, &uv)) continue;
        ++checked_lane;
        const auto it = lane_value.find(line.id);
        if (it == lane_value.end() || !NearValue(frame.mask, uv, it->second)) ++wrong_lane;
      }
    }
  }
  EXPECT_GT(checked_interior, 200);
  EXPECT_GT(checked_lane, 500);
  EXPECT_GT(checked_rects, 10);
  EXPECT_EQ(wrong_interior, 0) << "of " << checked_interior;
  EXPECT_EQ(wrong_lane, 0) << "of " << checked_lane;
}

TEST_P(SimGroundTruthTest, RectanglesAreOnTheSurfaceCounterClockwiseAndCentered) {
  const GroundTruth gt = drive_->ground_truth();
  const RoadModel& road = drive_->world().road();
  ASSERT_FALSE(gt.markings.empty());
  for (const GroundTruthMarking& m : gt.markings) {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    double twice_area = 0.0;
    for (int i = 0; i < 4; ++i) {
      const Eigen::Vector3d& a = m.corners_map[i];
      const Eigen::Vector3d& b = m.corners_map[(i + 1) % 4];
      twice_area += a.x() * b.y() - b.x() * a.y();
      mean += 0.25 * a;
      const Eigen::Vector2d sl = road.Locate(a.head<2>(), a.x());
      EXPECT_NEAR(a.z(), road.Height(sl.x(), sl.y()), 1e-6);
    }
    EXPECT_GT(twice_area, 0.0) << "marking " << m.id << " is not counter-clockwise";
    EXPECT_LT((mean - m.center_map).norm(), 1e-9);
  }
  // Lane points: dense (about 0.1 m apart) and on the surface.
  for (const GroundTruthLane& lane : gt.lanes) {
    ASSERT_GT(lane.points_map.size(), 100u);
    for (std::size_t i = 1; i < lane.points_map.size(); ++i) {
      const double gap = (lane.points_map[i] - lane.points_map[i - 1]).norm();
      EXPECT_GT(gap, 0.08);
      EXPECT_LT(gap, 0.12);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Scenarios, SimGroundTruthTest,
                         ::testing::Values("public_road", "port", "hilly"));

}  // namespace
}  // namespace sim
}  // namespace ipm_road_mapper
