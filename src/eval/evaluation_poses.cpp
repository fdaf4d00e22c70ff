// Extrinsic (with its IPM grid error) and pose evaluation.
#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <vector>

#include "ipm_road_mapper/core/geometry/ipm.h"
#include "ipm_road_mapper/eval/evaluation.h"

namespace ipm_road_mapper {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;
// The IPM grid must not lose pixels to the range check: the band limits select them.
constexpr double kUnlimitedRange_m = 1e9;

// Roll, pitch, yaw (deg) of the rotation R_est R_true^T, i.e. the error as a rotation about
// the axes of the frame both transforms map into (base_link for extrinsics).
Eigen::Vector3d RpyErrorDeg(const Eigen::Isometry3d& T_est, const Eigen::Isometry3d& T_true) {
  return RpyFromRotation(T_est.linear() * T_true.linear().transpose()) * kRadToDeg;
}

// |yaw(T_est) - yaw(T_true)| wrapped to [0, 180] deg.
double YawErrorDeg(const Eigen::Isometry3d& T_est, const Eigen::Isometry3d& T_true) {
  const double yaw_diff =
      RpyFromRotation(T_est.linear()).z() - RpyFromRotation(T_true.linear()).z();
  return std::abs(std::remainder(yaw_diff, 2.0 * M_PI)) * kRadToDeg;
}

// Mean ground distance between the IPM of grid pixels under T_base_cam_est and under the
// truth, over the pixels whose true ground point is in the evaluation band.
ErrorSummary IpmGridError(const GroundTruth& gt, const Eigen::Isometry3d& T_base_cam_est,
                          const EvaluationOptions& options, int* pixels, int* failed) {
  *pixels = 0;
  *failed = 0;
  const PinholeCamera camera(gt.camera);
  if (!camera.Validate().empty() || options.ipm_grid_step_px <= 0) return {};
  const Ipm ipm_true(camera, gt.T_base_cam_true, kUnlimitedRange_m);
  const Ipm ipm_est(camera, T_base_cam_est, kUnlimitedRange_m);
  const int step = options.ipm_grid_step_px;
  std::vector<double> errors;
  for (int v = step / 2; v < camera.height(); v += step) {
    for (int u = step / 2; u < camera.width(); u += step) {
      const Eigen::Vector2d uv(u, v);
      Eigen::Vector3d p_base_true, p_base_est;
      if (ipm_true.PixelToGround(uv, &p_base_true) != IpmStatus::kOk) continue;
      if (p_base_true.x() < options.ipm_grid_min_ahead_m ||
          p_base_true.x() > options.ipm_grid_max_ahead_m) {
        continue;
      }
      ++*pixels;
      if (ipm_est.PixelToGround(uv, &p_base_est) != IpmStatus::kOk) {
        ++*failed;
        continue;
      }
      errors.push_back((p_base_est - p_base_true).norm());
    }
  }
  return Summarize(std::move(errors));
}

// Index of the GT frame nearest in stamp to `stamp`, or -1 beyond the tolerance.
// `order` holds frame indices sorted by stamp.
int NearestFrame(const GroundTruth& gt, const std::vector<int>& order, double stamp,
                 double tolerance_s) {
  const auto after = std::lower_bound(order.begin(), order.end(), stamp,
                                      [&](int i, double s) { return gt.frames[i].stamp < s; });
  int best = -1;
  double best_dt = tolerance_s;
  for (auto it : {after - (after == order.begin() ? 0 : 1), after}) {
    if (it == order.end()) continue;
    const double dt = std::abs(gt.frames[*it].stamp - stamp);
    if (dt <= best_dt) {
      best_dt = dt;
      best = *it;
    }
  }
  return best;
}

// The calibration's error over its reported covariance (ExtrinsicMetrics::err_sigmas,
// nees_observed).
void EvaluateCalibrationConsistency(const VectorMap& map, const Eigen::Isometry3d& T_true,
                                    ExtrinsicMetrics* m) {
  const Eigen::Matrix<double, 6, 6>& sigma = map.T_base_cam_covariance;
  Eigen::Matrix<double, 6, 1> e;
  const Eigen::AngleAxisd rotation_error(T_true.linear() * map.T_base_cam.linear().transpose());
  e.head<3>() = rotation_error.angle() * rotation_error.axis();
  e.tail<3>() = T_true.translation() - map.T_base_cam.translation();
  for (int i = 0; i < 6; ++i) {
    if (sigma(i, i) > 0.0) m->err_sigmas(i) = e(i) / std::sqrt(sigma(i, i));
  }
  std::vector<int> observed;
  for (int i = 0; i < 6; ++i) {
    if (map.T_base_cam_observed[i] && sigma(i, i) > 0.0) observed.push_back(i);
  }
  if (observed.empty()) return;
  const int n = static_cast<int>(observed.size());
  Eigen::MatrixXd sigma_oo(n, n);
  Eigen::VectorXd e_o(n);
  for (int r = 0; r < n; ++r) {
    e_o(r) = e(observed[r]);
    for (int c = 0; c < n; ++c) sigma_oo(r, c) = sigma(observed[r], observed[c]);
  }
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(sigma_oo);
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) return;
  m->nees_observed = e_o.dot(ldlt.solve(e_o));
  m->nees_dof = n;
}

// GT frame indices sorted by stamp.
std::vector<int> FramesByStamp(const GroundTruth& gt) {
  std::vector<int> order(gt.frames.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
  std::sort(order.begin(), order.end(),
            [&](int a, int b) { return gt.frames[a].stamp < gt.frames[b].stamp; });
  return order;
}

// Per GT frame: whether its true speed (from its neighbours in time, one-sided at the ends)
// is at least `min_speed_mps`. A lone frame does not move.
std::vector<bool> MovingFrames(const GroundTruth& gt, const std::vector<int>& order,
                               double min_speed_mps) {
  std::vector<bool> moving(gt.frames.size(), false);
  const int n = static_cast<int>(order.size());
  for (int k = 0; k < n; ++k) {
    const GroundTruthFrame& a = gt.frames[order[std::max(0, k - 1)]];
    const GroundTruthFrame& b = gt.frames[order[std::min(n - 1, k + 1)]];
    const double dt = b.stamp - a.stamp;
    if (dt <= 0.0) continue;
    const double distance_m =
        (b.T_map_base_true.translation() - a.T_map_base_true.translation()).norm();
    moving[order[k]] = distance_m >= min_speed_mps * dt;
  }
  return moving;
}

// Pairs (GT frame, corrected pose or nullptr): the map's poses matched by stamp (those
// without a GT frame counted in *unmatched), or every GT frame when the map has no
// trajectory (then only the odometry is measured). `order`: FramesByStamp(gt).
std::vector<std::pair<int, const StampedPose*>> PairPoses(const VectorMap& map,
                                                          const GroundTruth& gt,
                                                          const std::vector<int>& order,
                                                          const EvaluationOptions& options,
                                                          int* unmatched) {
  std::vector<std::pair<int, const StampedPose*>> pairs;
  if (map.trajectory.empty()) {
    for (std::size_t i = 0; i < gt.frames.size(); ++i) {
      pairs.emplace_back(static_cast<int>(i), nullptr);
    }
    return pairs;
  }
  for (const StampedPose& pose : map.trajectory) {
    const int frame = NearestFrame(gt, order, pose.stamp, options.pose_stamp_tolerance_s);
    if (frame < 0) {
      ++*unmatched;
    } else {
      pairs.emplace_back(frame, &pose);
    }
  }
  return pairs;
}

// The translation error in the true base_link axes: x along the heading, y across it.
Eigen::Vector3d InBase(const Eigen::Isometry3d& T_est, const Eigen::Isometry3d& T_true) {
  return Eigen::Vector3d(T_true.linear().transpose() *
                         (T_est.translation() - T_true.translation()));
}

}  // namespace

ExtrinsicMetrics EvaluateExtrinsic(const VectorMap& map, const GroundTruth& gt,
                                   const EvaluationOptions& options) {
  ExtrinsicMetrics m;
  const Eigen::Isometry3d& T_true = gt.T_base_cam_true;
  m.rot_err_deg = RotationAngleBetween(map.T_base_cam, T_true) * kRadToDeg;
  m.rot_err_deg_initial = RotationAngleBetween(map.T_base_cam_initial, T_true) * kRadToDeg;
  m.rpy_err_deg = RpyErrorDeg(map.T_base_cam, T_true);
  m.rpy_err_deg_initial = RpyErrorDeg(map.T_base_cam_initial, T_true);
  m.trans_err_xyz_m = map.T_base_cam.translation() - T_true.translation();
  m.trans_err_xyz_m_initial = map.T_base_cam_initial.translation() - T_true.translation();
  m.true_xyz_m = T_true.translation();
  m.true_rpy_deg = RpyFromRotation(T_true.linear()) * kRadToDeg;
  m.trans_err_m = m.trans_err_xyz_m.norm();
  m.trans_err_m_initial = m.trans_err_xyz_m_initial.norm();
  int pixels_initial = 0;
  m.ipm_grid_err_m =
      IpmGridError(gt, map.T_base_cam, options, &m.ipm_grid_pixels, &m.ipm_grid_failed);
  m.ipm_grid_err_m_initial = IpmGridError(gt, map.T_base_cam_initial, options, &pixels_initial,
                                          &m.ipm_grid_failed_initial);
  EvaluateCalibrationConsistency(map, T_true, &m);
  return m;
}

PoseMetrics EvaluatePoses(const VectorMap& map, const GroundTruth& gt,
                          const EvaluationOptions& options) {
  PoseMetrics metrics;
  metrics.has_trajectory = !map.trajectory.empty();
  const std::vector<int> order = FramesByStamp(gt);
  const std::vector<bool> moving = MovingFrames(gt, order, options.pose_moving_min_speed_mps);
  const std::vector<std::pair<int, const StampedPose*>> pairs =
      PairPoses(map, gt, order, options, &metrics.map_poses_unmatched);

  std::vector<double> trans, rot, yaw, trans_input, rot_input, yaw_input;
  std::vector<double> along, across, along_input, across_input, moving_trans, moving_input;
  for (const auto& [frame_index, pose] : pairs) {
    const GroundTruthFrame& frame = gt.frames[frame_index];
    PoseFrameError e;
    e.stamp = frame.stamp;
    e.moving = moving[frame_index];
    e.trans_err_m_input =
        (frame.T_map_base_odom.translation() - frame.T_map_base_true.translation()).norm();
    e.rot_err_deg_input =
        RotationAngleBetween(frame.T_map_base_odom, frame.T_map_base_true) * kRadToDeg;
    e.yaw_err_deg_input = YawErrorDeg(frame.T_map_base_odom, frame.T_map_base_true);
    trans_input.push_back(e.trans_err_m_input);
    rot_input.push_back(e.rot_err_deg_input);
    yaw_input.push_back(e.yaw_err_deg_input);
    if (e.moving) moving_input.push_back(e.trans_err_m_input);
    const Eigen::Vector3d e_input = InBase(frame.T_map_base_odom, frame.T_map_base_true);
    along_input.push_back(std::abs(e_input.x()));
    across_input.push_back(std::abs(e_input.y()));
    if (pose == nullptr) {
      e.trans_err_m = e.rot_err_deg = e.yaw_err_deg = kNoValue;
    } else {
      e.trans_err_m = (pose->T_map_base.translation() - frame.T_map_base_true.translation()).norm();
      e.rot_err_deg = RotationAngleBetween(pose->T_map_base, frame.T_map_base_true) * kRadToDeg;
      e.yaw_err_deg = YawErrorDeg(pose->T_map_base, frame.T_map_base_true);
      trans.push_back(e.trans_err_m);
      rot.push_back(e.rot_err_deg);
      yaw.push_back(e.yaw_err_deg);
      if (e.moving) moving_trans.push_back(e.trans_err_m);
      const Eigen::Vector3d e_base = InBase(pose->T_map_base, frame.T_map_base_true);
      along.push_back(std::abs(e_base.x()));
      across.push_back(std::abs(e_base.y()));
    }
    metrics.frames.push_back(e);
  }
  metrics.frames_matched = metrics.has_trajectory ? static_cast<int>(pairs.size()) : 0;
  metrics.frames_moving = static_cast<int>(moving_input.size());
  metrics.trans_err_m = Summarize(std::move(trans));
  metrics.rot_err_deg = Summarize(std::move(rot));
  metrics.yaw_err_deg = Summarize(std::move(yaw));
  metrics.trans_err_m_input = Summarize(std::move(trans_input));
  metrics.rot_err_deg_input = Summarize(std::move(rot_input));
  metrics.yaw_err_deg_input = Summarize(std::move(yaw_input));
  metrics.along_err_m = Summarize(std::move(along));
  metrics.across_err_m = Summarize(std::move(across));
  metrics.along_err_m_input = Summarize(std::move(along_input));
  metrics.across_err_m_input = Summarize(std::move(across_input));
  metrics.trans_err_moving_m = Summarize(std::move(moving_trans));
  metrics.trans_err_moving_m_input = Summarize(std::move(moving_input));
  return metrics;
}

}  // namespace ipm_road_mapper
