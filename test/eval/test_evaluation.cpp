// The map evaluation on a small synthetic drive built here: a straight 60 m road with a
// grade, 3 lane lines (2 lanes), 3 markings. A map made from the ground truth must score
// perfectly, and each kind of damage must show in exactly the metric that measures it.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "ipm_road_mapper/eval/evaluation.h"

namespace ipm_road_mapper {
namespace {

constexpr double kDegToRad = M_PI / 180.0;

// Road surface height: a 2% grade and a small cross slope (the road is not a plane).
double RoadZ(double x, double y) { return 0.02 * x + 0.01 * y; }

// Axis-aligned marking of size length x width centered at (x, y), corners counter-clockwise.
GroundTruthMarking MakeMarking(int id, int class_id, double x, double y, double length,
                               double width) {
  GroundTruthMarking m;
  m.id = id;
  m.class_id = class_id;
  m.class_name = class_id == 10 ? "arrow_straight" : "diamond";
  const double dx[4] = {-0.5, 0.5, 0.5, -0.5}, dy[4] = {-0.5, -0.5, 0.5, 0.5};
  m.center_map.setZero();
  for (int k = 0; k < 4; ++k) {
    const double cx = x + dx[k] * length, cy = y + dy[k] * width;
    m.corners_map[k] = Eigen::Vector3d(cx, cy, RoadZ(cx, cy));
    m.center_map += 0.25 * m.corners_map[k];
  }
  m.visible_frames = 20;
  return m;
}

Eigen::Isometry3d CameraExtrinsic(double pitch_down_deg, double height_m) {
  Eigen::Matrix3d R_base_cam_level;  // columns: camera x (right), y (down), z (forward)
  R_base_cam_level << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = RotationFromRpy(0.0, pitch_down_deg * kDegToRad, 0.0) * R_base_cam_level;
  T.translation() = Eigen::Vector3d(1.5, 0.0, height_m);
  return T;
}

GroundTruth MakeGroundTruth() {
  GroundTruth gt;
  gt.scenario = "test_straight";
  gt.camera.width = 1280;
  gt.camera.height = 720;
  gt.camera.fx = gt.camera.fy = 1000.0;
  gt.camera.cx = 640.0;
  gt.camera.cy = 360.0;
  gt.T_base_cam_true = CameraExtrinsic(3.0, 1.4);
  gt.T_base_cam_rough = CameraExtrinsic(2.0, 1.45);
  int id = 0;
  for (double y : {-1.75, 1.75, 5.25}) {
    GroundTruthLane lane;
    lane.id = ++id;
    lane.class_id = 1;
    lane.class_name = "lane_white_solid";
    for (int k = 0; k <= 600; ++k) lane.points_map.emplace_back(0.1 * k, y, RoadZ(0.1 * k, y));
    gt.lanes.push_back(lane);
  }
  gt.markings.push_back(MakeMarking(1, 10, 15.0, 0.0, 4.0, 1.0));
  gt.markings.push_back(MakeMarking(2, 10, 35.0, 0.0, 4.0, 1.0));
  gt.markings.push_back(MakeMarking(3, 23, 25.0, 3.5, 3.0, 1.2));
  for (int k = 0; k < 60; ++k) {
    GroundTruthFrame frame;
    frame.stamp = 100.0 + 0.05 * k;
    frame.T_map_base_true.translation() = Eigen::Vector3d(k, 0.0, RoadZ(k, 0.0));
    frame.T_map_base_odom = frame.T_map_base_true;
    frame.T_map_base_odom.translation() += Eigen::Vector3d(0.004 * k, 0.2, 0.0);
    frame.T_map_base_odom.linear() = RotationFromRpy(0.0, 0.0, 0.5 * kDegToRad);
    gt.frames.push_back(frame);
  }
  return gt;
}

// Control points through GT points every `stride` points, with phantom ends extrapolated.
std::vector<Eigen::Vector3d> ControlPointsThrough(const std::vector<Eigen::Vector3d>& points,
                                                  std::size_t begin, std::size_t end,
                                                  std::size_t stride) {
  std::vector<Eigen::Vector3d> through;
  for (std::size_t k = begin; k < end; k += stride) through.push_back(points[k]);
  if (through.size() < 2 || (through.back() - points[end - 1]).norm() > 1e-12) {
    through.push_back(points[end - 1]);
  }
  std::vector<Eigen::Vector3d> control{2.0 * through[0] - through[1]};
  control.insert(control.end(), through.begin(), through.end());
  control.push_back(2.0 * through.back() - through[through.size() - 2]);
  return control;
}

MapLane LaneFromPoints(std::uint64_t id, const std::vector<Eigen::Vector3d>& points,
                       std::size_t begin, std::size_t end) {
  MapLane lane;
  lane.id = id;
  lane.class_name = "lane_white_solid";
  lane.control_points_map = ControlPointsThrough(points, begin, end, 30);  // every 3 m
  return lane;
}

// The map a perfect mapper would export.
VectorMap PerfectMap(const GroundTruth& gt) {
  VectorMap map;
  for (const GroundTruthMarking& g : gt.markings) {
    MapMarking m;
    m.id = 100 + g.id;
    m.class_id = g.class_id;
    m.class_name = g.class_name;
    m.corners_map = g.corners_map;
    map.markings.push_back(m);
  }
  for (const GroundTruthLane& g : gt.lanes) {
    map.lanes.push_back(LaneFromPoints(200 + g.id, g.points_map, 0, g.points_map.size()));
  }
  map.T_base_cam = gt.T_base_cam_true;
  map.T_base_cam_initial = gt.T_base_cam_rough;
  for (const GroundTruthFrame& frame : gt.frames) {
    map.trajectory.push_back({frame.stamp, frame.T_map_base_true});
  }
  return map;
}

VectorMap Shifted(VectorMap map, const Eigen::Vector3d& shift) {
  for (MapMarking& m : map.markings) {
    for (Eigen::Vector3d& c : m.corners_map) c += shift;
  }
  for (MapLane& lane : map.lanes) {
    for (Eigen::Vector3d& c : lane.control_points_map) c += shift;
  }
  return map;
}

class EvaluationTest : public ::testing::Test {
 protected:
  GroundTruth gt_ = MakeGroundTruth();
  VectorMap map_ = PerfectMap(gt_);
  EvaluationOptions options_;
};

TEST_F(EvaluationTest, PerfectMapScoresPerfectly) {
  const Metrics m = EvaluateMap(map_, gt_, options_);
  EXPECT_EQ(m.markings.matched, 3);
  EXPECT_LT(m.markings.center_error_m.max, 1e-6);
  EXPECT_LT(m.markings.corner_error_m.max, 1e-6);
  EXPECT_DOUBLE_EQ(m.markings.recall, 1.0);
  EXPECT_EQ(m.markings.duplicates, 0);
  EXPECT_EQ(m.markings.unmatched_map, 0);
  EXPECT_LT(m.lanes.error_m.mean, 0.01);
  EXPECT_LT(m.lanes.error_m.max, 0.01);
  EXPECT_GT(m.lanes.error_m.count, 3 * 590);
  EXPECT_DOUBLE_EQ(m.lanes.f1, 1.0);
  EXPECT_DOUBLE_EQ(m.lanes.precision, 1.0);
  EXPECT_DOUBLE_EQ(m.lanes.recall, 1.0);
  EXPECT_DOUBLE_EQ(m.lanes.splines_per_matched_gt_lane, 1.0);
  EXPECT_NEAR(m.lanes.mapped_length_m, 3 * 60.0 * std::hypot(1.0, 0.02), 1e-6);
  EXPECT_LT(m.extrinsic.rot_err_deg, 1e-6);
  EXPECT_LT(m.extrinsic.trans_err_m, 1e-12);
  EXPECT_GT(m.extrinsic.ipm_grid_pixels, 50);
  EXPECT_LT(m.extrinsic.ipm_grid_err_m.mean, 1e-6);
  EXPECT_NEAR(m.extrinsic.rot_err_deg_initial, 1.0, 1e-9);
  EXPECT_GT(m.extrinsic.ipm_grid_err_m_initial.mean, 0.5);  // 1 deg of pitch at 5-30 m
  EXPECT_EQ(m.poses.frames_matched, 60);
  EXPECT_LT(m.poses.trans_err_m.max, 1e-12);
  EXPECT_NEAR(m.poses.yaw_err_deg_input.mean, 0.5, 1e-9);
  EXPECT_NEAR(m.poses.rot_err_deg_input.mean, 0.5, 1e-9);

  // Samples between the GT points still measure 0: the GT lanes are lines, not points.
  options_.lane_sample_spacing_m = 0.07;
  EXPECT_LT(EvaluateLanes(map_, gt_, options_).error_m.max, 1e-6);
}

TEST_F(EvaluationTest, ShiftedMapShowsTheShift) {
  const Metrics along = EvaluateMap(Shifted(map_, {0.3, 0.0, 0.0}), gt_, options_);
  EXPECT_NEAR(along.markings.center_error_m.mean, 0.3, 1e-6);
  EXPECT_NEAR(along.markings.center_error_m.stddev, 0.0, 1e-6);
  EXPECT_NEAR(along.markings.corner_error_m.mean, 0.3, 1e-6);
  EXPECT_NEAR(along.markings.mean_abs_error_xyz_m.x(), 0.3, 1e-6);
  EXPECT_NEAR(along.markings.signed_mean_error_xyz_m.x(), 0.3, 1e-6);
  EXPECT_NEAR(along.markings.mean_abs_error_xyz_m.y(), 0.0, 1e-6);
  EXPECT_LE(along.lanes.error_m.mean, 0.3);
  EXPECT_LE(along.lanes.error_m.max, 0.3 + 1e-6);  // the 0.3 m past the GT end

  const Metrics across = EvaluateMap(Shifted(map_, {0.0, -0.3, 0.0}), gt_, options_);
  EXPECT_NEAR(across.markings.signed_mean_error_xyz_m.y(), -0.3, 1e-6);
  EXPECT_NEAR(across.lanes.error_m.mean, 0.3, 1e-6);  // the offset is normal to the lanes
  EXPECT_NEAR(across.lanes.error_xy_mean_m, 0.3, 1e-6);
  EXPECT_DOUBLE_EQ(across.lanes.f1, 1.0);  // 0.3 m is within the 0.5 m gate

  const Metrics far = EvaluateMap(Shifted(map_, {0.0, 0.8, 0.0}), gt_, options_);
  EXPECT_DOUBLE_EQ(far.lanes.f1, 0.0);  // every sample 0.8 m off: no lane matches
  EXPECT_NEAR(far.markings.center_error_m.mean, 0.8, 1e-6);
}

TEST_F(EvaluationTest, DuplicateAndMissingMarkings) {
  MapMarking copy = map_.markings[0];
  copy.id = 999;
  for (Eigen::Vector3d& c : copy.corners_map) c.x() += 0.5;
  map_.markings.push_back(copy);
  const MarkingMetrics duplicated = EvaluateMarkings(map_, gt_, options_);
  EXPECT_EQ(duplicated.duplicates, 1);
  EXPECT_EQ(duplicated.unmatched_map, 1);
  EXPECT_DOUBLE_EQ(duplicated.recall, 1.0);
  EXPECT_LT(duplicated.center_error_m.max, 1e-6);  // the exact copy won the match
  EXPECT_EQ(duplicated.gt_markings[0].duplicates, 1);
  EXPECT_EQ(duplicated.map_markings.back().verdict, MarkingVerdict::kDuplicate);

  map_.markings.pop_back();
  map_.markings.erase(map_.markings.begin() + 2);  // the diamond
  const MarkingMetrics missing = EvaluateMarkings(map_, gt_, options_);
  EXPECT_NEAR(missing.recall, 2.0 / 3.0, 1e-12);
  EXPECT_FALSE(missing.gt_markings[2].matched);
  // A GT marking never seen does not count against recall.
  gt_.markings[2].visible_frames = 0;
  EXPECT_DOUBLE_EQ(EvaluateMarkings(map_, gt_, options_).recall, 1.0);
}

TEST_F(EvaluationTest, MarkingsMatchOnlyTheirClassWithinTheGate) {
  map_.markings[2].class_id = 10;  // the diamond mapped as an arrow
  for (Eigen::Vector3d& c : map_.markings[1].corners_map) c.x() += 2.5;  // beyond the gate
  const MarkingMetrics m = EvaluateMarkings(map_, gt_, options_);
  EXPECT_EQ(m.matched, 1);
  EXPECT_EQ(m.unmatched_map, 2);
  EXPECT_EQ(m.duplicates, 0);
  EXPECT_NEAR(m.recall, 1.0 / 3.0, 1e-12);
  EXPECT_NEAR(m.precision, 1.0 / 3.0, 1e-12);
}

TEST_F(EvaluationTest, LaneF1CountsMissingSpuriousAndSplitLanes) {
  VectorMap missing = map_;
  missing.lanes.pop_back();
  LaneMetrics m = EvaluateLanes(missing, gt_, options_);
  EXPECT_NEAR(m.recall, 2.0 / 3.0, 1e-12);
  EXPECT_DOUBLE_EQ(m.precision, 1.0);
  EXPECT_NEAR(m.f1, 0.8, 1e-12);

  VectorMap spurious = map_;
  spurious.lanes.push_back(Shifted(map_, {0.0, 15.0, 0.0}).lanes[0]);
  spurious.lanes.back().id = 300;
  m = EvaluateLanes(spurious, gt_, options_);
  EXPECT_DOUBLE_EQ(m.recall, 1.0);
  EXPECT_DOUBLE_EQ(m.precision, 0.75);
  EXPECT_FALSE(m.map_lanes.back().true_positive);
  EXPECT_NEAR(m.error_m.max, 8.0, 0.01);  // y = -1.75 + 15 lies 8 m from y = 5.25

  VectorMap split = map_;
  const std::vector<Eigen::Vector3d>& points = gt_.lanes[0].points_map;
  split.lanes[0] = LaneFromPoints(400, points, 0, 301);
  split.lanes.push_back(LaneFromPoints(401, points, 300, points.size()));
  m = EvaluateLanes(split, gt_, options_);
  EXPECT_DOUBLE_EQ(m.f1, 1.0);
  EXPECT_EQ(m.gt_lanes[0].covering_map_ids, (std::vector<std::uint64_t>{400, 401}));
  EXPECT_NEAR(m.splines_per_matched_gt_lane, 4.0 / 3.0, 1e-12);

  VectorMap half = map_;
  half.lanes[1] = LaneFromPoints(500, gt_.lanes[1].points_map, 0, 301);  // covers 50%
  m = EvaluateLanes(half, gt_, options_);
  EXPECT_NEAR(m.gt_lanes[1].coverage, 0.51, 0.01);  // x <= 30.5 m of 60 m
  EXPECT_FALSE(m.gt_lanes[1].matched);
  EXPECT_TRUE(m.map_lanes[1].true_positive);
}

TEST_F(EvaluationTest, LaneStretchesNoPixelMeasuredAreScoredApart) {
  // Lane 0's control points every 3 m from x 0 (index 1): points 5-7 (x 12-18 m) laid 0.3 m
  // beside the line by a join. The laid stretch runs from point 4 to point 8 (x 9-21 m).
  VectorMap laid = map_;
  MapLane& lane = laid.lanes[0];
  for (std::size_t i = 5; i <= 7; ++i) lane.control_points_map[i].y() += 0.3;
  LaneMetrics m = EvaluateLanes(laid, gt_, options_);
  EXPECT_DOUBLE_EQ(m.unmeasured_length_m, 0.0);  // not flagged: scored as measured
  EXPECT_EQ(m.error_unmeasured_m.count, 0);
  EXPECT_GT(m.error_measured_m.max, 0.29);
  lane.unmeasured = {{5, 7}};
  m = EvaluateLanes(laid, gt_, options_);
  EXPECT_NEAR(m.unmeasured_length_m, 12.0, 0.3);
  EXPECT_GT(m.error_unmeasured_m.mean, 0.15);
  // The rest lies on the line, but for the segment before the stretch, which a moved point
  // also shapes (a Catmull-Rom segment depends on four points).
  EXPECT_LT(m.error_measured_m.max, 0.05);
  EXPECT_EQ(m.error_unmeasured_m.count + m.error_measured_m.count, m.error_m.count);
}

TEST_F(EvaluationTest, ExtrinsicErrorIsTheAppliedRotationAndTranslation) {
  const Eigen::Vector3d axis = Eigen::Vector3d(0.3, -1.0, 0.2).normalized();
  map_.T_base_cam.linear() =
      Eigen::AngleAxisd(0.7 * kDegToRad, axis).toRotationMatrix() * gt_.T_base_cam_true.linear();
  map_.T_base_cam.translation() += Eigen::Vector3d(0.03, 0.0, -0.04);
  const ExtrinsicMetrics m = EvaluateExtrinsic(map_, gt_, options_);
  EXPECT_NEAR(m.rot_err_deg, 0.7, 1e-9);
  EXPECT_NEAR(m.trans_err_m, 0.05, 1e-12);
  EXPECT_NEAR(m.trans_err_xyz_m.z(), -0.04, 1e-12);
  EXPECT_GT(m.ipm_grid_err_m.mean, 0.05);
  EXPECT_LT(m.ipm_grid_err_m.mean, m.ipm_grid_err_m_initial.mean);

  // Pure pitch shows as pitch in the roll-pitch-yaw error of base_link.
  map_.T_base_cam = gt_.T_base_cam_true;
  map_.T_base_cam.linear() = RotationFromRpy(0.0, 0.4 * kDegToRad, 0.0) * map_.T_base_cam.linear();
  const ExtrinsicMetrics pitch = EvaluateExtrinsic(map_, gt_, options_);
  EXPECT_NEAR(pitch.rpy_err_deg.y(), 0.4, 1e-9);
  EXPECT_NEAR(pitch.rpy_err_deg.x(), 0.0, 1e-9);
}

TEST_F(EvaluationTest, CalibrationConsistencyIsTheErrorOverTheMapsOwnCovariance) {
  // No covariance in the map: no consistency figure.
  ExtrinsicMetrics m = EvaluateExtrinsic(map_, gt_, options_);
  EXPECT_EQ(m.nees_dof, 0);
  EXPECT_TRUE(std::isnan(m.nees_observed));
  EXPECT_TRUE(std::isnan(m.err_sigmas(0)));

  // 0.2 deg of yaw and 3 cm of height too high; the map claims 0.1 deg and 1 cm.
  map_.T_base_cam = gt_.T_base_cam_true;
  map_.T_base_cam.linear() = RotationFromRpy(0.0, 0.0, 0.2 * kDegToRad) * map_.T_base_cam.linear();
  map_.T_base_cam.translation().z() += 0.03;
  Eigen::Matrix<double, 6, 1> sigma;
  sigma << 0.1 * kDegToRad, 0.1 * kDegToRad, 0.1 * kDegToRad, 0.05, 0.05, 0.01;
  map_.T_base_cam_covariance = sigma.cwiseAbs2().asDiagonal();
  map_.T_base_cam_observed = {true, true, true, false, false, true};
  m = EvaluateExtrinsic(map_, gt_, options_);
  // The covariance's error is the truth's side: R_true = Exp(e) R, t_true - t.
  EXPECT_NEAR(m.err_sigmas(2), -2.0, 1e-6);
  EXPECT_NEAR(m.err_sigmas(5), -3.0, 1e-9);
  EXPECT_NEAR(m.err_sigmas(0), 0.0, 1e-6);
  EXPECT_NEAR(m.err_sigmas(3), 0.0, 1e-12);
  EXPECT_EQ(m.nees_dof, 4);
  EXPECT_NEAR(m.nees_observed, 4.0 + 9.0, 1e-5);

  // A correlation the error runs against raises the NEES; the diagonal sigmas stay.
  map_.T_base_cam_covariance(2, 5) = map_.T_base_cam_covariance(5, 2) = 0.8 * sigma(2) * sigma(5);
  m = EvaluateExtrinsic(map_, gt_, options_);
  EXPECT_NEAR(m.err_sigmas(2), -2.0, 1e-6);
  // [-2 -3] over [[1 .8] [.8 1]]: (4 + 9 - 2 * .8 * 6) / (1 - .64).
  EXPECT_NEAR(m.nees_observed, (13.0 - 9.6) / 0.36, 1e-4);
}

TEST_F(EvaluationTest, PoseErrorIsTheAppliedShift) {
  for (StampedPose& pose : map_.trajectory) {
    pose.T_map_base.translation() += Eigen::Vector3d(0.2, -0.1, 0.0);
    pose.T_map_base.linear() = RotationFromRpy(0.0, 0.0, -1.0 * kDegToRad);
    pose.stamp += 0.0004;  // within the 1 ms association tolerance
  }
  map_.trajectory.push_back({500.0, Eigen::Isometry3d::Identity()});  // no GT frame there
  const PoseMetrics m = EvaluatePoses(map_, gt_, options_);
  EXPECT_EQ(m.frames_matched, 60);
  EXPECT_EQ(m.map_poses_unmatched, 1);
  EXPECT_NEAR(m.trans_err_m.mean, std::hypot(0.2, 0.1), 1e-12);
  EXPECT_NEAR(m.trans_err_m.stddev, 0.0, 1e-12);
  EXPECT_NEAR(m.rot_err_deg.mean, 1.0, 1e-9);
  EXPECT_NEAR(m.yaw_err_deg.mean, 1.0, 1e-9);
  EXPECT_NEAR(m.trans_err_m_input.max, std::hypot(0.004 * 59, 0.2), 1e-9);
  // The split along / across the true heading: the shift in each true base_link's axes.
  double along = 0.0, across = 0.0;
  for (const GroundTruthFrame& frame : gt_.frames) {
    const Eigen::Vector3d e =
        frame.T_map_base_true.linear().transpose() * Eigen::Vector3d(0.2, -0.1, 0.0);
    along += std::abs(e.x()) / gt_.frames.size();
    across += std::abs(e.y()) / gt_.frames.size();
  }
  EXPECT_NEAR(m.along_err_m.mean, along, 1e-9);
  EXPECT_NEAR(m.across_err_m.mean, across, 1e-9);
  EXPECT_NEAR(std::hypot(m.along_err_m.mean, m.across_err_m.mean), std::hypot(0.2, 0.1), 0.05);
  EXPECT_LE(m.along_err_m_input.mean, m.trans_err_m_input.mean + 1e-12);

  map_.trajectory.clear();
  const Metrics without = EvaluateMap(map_, gt_, options_);
  EXPECT_FALSE(without.poses.has_trajectory);
  EXPECT_EQ(without.poses.trans_err_m.count, 0);
  EXPECT_EQ(without.poses.trans_err_m_input.count, 60);
  const nlohmann::json j = MetricsToJson(without);
  EXPECT_TRUE(j["pose_trans_err_m"].is_null());
  EXPECT_TRUE(j["pose_trans_err_m_input"].is_number());
  EXPECT_NE(FormatMetricsTable(without).find("no trajectory"), std::string::npos);
}

TEST_F(EvaluationTest, StorageAndJsonKeys) {
  options_.map_bytes = 9000;
  const Metrics m = EvaluateMap(map_, gt_, options_);
  const double km = 3 * 0.060 * std::hypot(1.0, 0.02);
  EXPECT_NEAR(m.storage.map_bytes_per_km, 9000 / km, 1e-6);
  EXPECT_NEAR(m.storage.control_points_per_km, 3 * 23 / km, 1e-6);
  const nlohmann::json j = MetricsToJson(m);
  for (const char* key :
       {"marking_ape_mean_m", "marking_ape_std_m", "marking_recall", "marking_duplicates",
        "lane_ape_mean_m", "lane_ape_std_m", "lane_f1", "extrinsic_rot_err_deg",
        "extrinsic_trans_err_m", "ipm_grid_err_m", "ipm_grid_err_m_initial",
        "pose_rot_err_deg_input", "pose_trans_err_m_input", "pose_rot_err_deg", "pose_trans_err_m",
        "map_bytes_per_km", "control_points_per_km"}) {
    ASSERT_TRUE(j.contains(key)) << key;
    EXPECT_TRUE(j[key].is_number()) << key;
  }
  EXPECT_EQ(j["markings"].size(), 3u);
  EXPECT_EQ(j["lanes"].size(), 3u);
  EXPECT_EQ(j["gt_lanes"].size(), 3u);
  EXPECT_EQ(j["poses"].size(), 60u);
  EXPECT_EQ(j["map_bytes_source"], "file");
  // Without a file size, the serialized map's size is used.
  EXPECT_GT(EvaluateStorage(map_, EvaluationOptions()).map_bytes, 1000);
  const std::string table = FormatMetricsTable(m);
  for (const char* heading : {"Markings", "Lanes", "Extrinsic", "Poses", "Storage"}) {
    EXPECT_NE(table.find(heading), std::string::npos) << heading;
  }
}

TEST_F(EvaluationTest, EmptyMapGivesZeroRecallAndNoErrors) {
  VectorMap empty;
  empty.T_base_cam = empty.T_base_cam_initial = gt_.T_base_cam_rough;
  const Metrics m = EvaluateMap(empty, gt_, options_);
  EXPECT_DOUBLE_EQ(m.markings.recall, 0.0);
  EXPECT_EQ(m.markings.center_error_m.count, 0);
  EXPECT_DOUBLE_EQ(m.lanes.f1, 0.0);
  EXPECT_TRUE(std::isnan(m.storage.map_bytes_per_km));
  EXPECT_TRUE(MetricsToJson(m)["marking_ape_mean_m"].is_null());
}

}  // namespace
}  // namespace ipm_road_mapper

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
