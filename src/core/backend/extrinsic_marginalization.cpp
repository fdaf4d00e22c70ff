#include "ipm_road_mapper/core/backend/extrinsic_marginalization.h"

#include <ceres/autodiff_cost_function.h>
#include <ceres/rotation.h>

#include <Eigen/Cholesky>
#include <memory>

#include "ipm_road_mapper/core/backend/residuals/corner_reprojection_residual.h"
#include "ipm_road_mapper/core/backend/residuals/road_surface_prior_residual.h"

namespace ipm_road_mapper {
namespace {

// Damping of the points' block before its inversion (m^-2): points the measurements see
// from too few directions must not blow up the Schur complement.
constexpr double kPointDamping = 1e-6;

// The extrinsic at `delta` in the chart (q0, t0): q = Exp(delta_rot) q0, t = t0 + delta_t.
template <typename T>
void ExtrinsicAtDelta(const Eigen::Quaterniond& q0, const Eigen::Vector3d& t0, const T* delta,
                      T* q_xyzw, T* t) {
  T dq_wxyz[4];
  ceres::AngleAxisToQuaternion(delta, dq_wxyz);
  const Eigen::Quaternion<T> dq(dq_wxyz[0], dq_wxyz[1], dq_wxyz[2], dq_wxyz[3]);
  const Eigen::Quaternion<T> q = dq * q0.cast<T>();
  q_xyzw[0] = q.x(), q_xyzw[1] = q.y(), q_xyzw[2] = q.z(), q_xyzw[3] = q.w();
  for (int i = 0; i < 3; ++i) t[i] = T(t0(i)) + delta[3 + i];
}

// Pose of a frame as the double blocks the residual functions take.
struct Pose {
  double q[4], t[3];
  explicit Pose(const Eigen::Isometry3d& T) {
    const Eigen::Quaterniond quaternion(T.linear());
    q[0] = quaternion.x(), q[1] = quaternion.y(), q[2] = quaternion.z(), q[3] = quaternion.w();
    for (int i = 0; i < 3; ++i) t[i] = T.translation()(i);
  }
};

// Corner reprojection with the extrinsic in the chart. Blocks: point[3], delta[6].
struct CornerInChart {
  PinholeCamera camera;
  Eigen::Vector2d uv;
  Eigen::Matrix2d sqrt_information;
  Pose pose;
  Eigen::Quaterniond q0;
  Eigen::Vector3d t0;
  template <typename T>
  bool operator()(const T* const point, const T* const delta, T* residual) const {
    T q[4], t[3];
    ExtrinsicAtDelta(q0, t0, delta, q, t);
    const T q_mb[4] = {T(pose.q[0]), T(pose.q[1]), T(pose.q[2]), T(pose.q[3])};
    const T t_mb[3] = {T(pose.t[0]), T(pose.t[1]), T(pose.t[2])};
    T error[2];
    if (!residuals::CornerReprojection(camera, uv, 1.0, point, q_mb, t_mb, q, t, error)) {
      return false;
    }
    for (int i = 0; i < 2; ++i) {
      residual[i] = T(sqrt_information(i, 0)) * error[0] + T(sqrt_information(i, 1)) * error[1];
    }
    return true;
  }
};

// Accumulates J^T W J and J^T W r over [points (3 each) ; delta (6)].
class NormalEquations {
 public:
  explicit NormalEquations(int num_points)
      : n_(3 * num_points + 6), H_(Eigen::MatrixXd::Zero(n_, n_)), g_(Eigen::VectorXd::Zero(n_)) {}

  // One residual block: its cost function, the column offsets of its parameter blocks
  // (-1 for data) and their values. Robust (Huber) weights when huber_scale > 0.
  void Add(const ceres::CostFunction& cost, const std::vector<int>& offsets,
           const std::vector<const double*>& values, double huber_scale) {
    const int m = cost.num_residuals();
    const std::vector<int32_t>& sizes = cost.parameter_block_sizes();
    std::vector<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> jacobians;
    std::vector<double*> jacobian_ptrs;
    for (int32_t size : sizes) {
      jacobians.emplace_back(m, size);
      jacobian_ptrs.push_back(jacobians.back().data());
    }
    Eigen::VectorXd r(m);
    if (!cost.Evaluate(values.data(), r.data(), jacobian_ptrs.data()) || !r.allFinite()) return;
    double w = 1.0;
    if (huber_scale > 0.0 && r.norm() > huber_scale) w = huber_scale / r.norm();
    Eigen::MatrixXd J = Eigen::MatrixXd::Zero(m, n_);
    for (std::size_t b = 0; b < sizes.size(); ++b) {
      if (offsets[b] >= 0) J.block(0, offsets[b], m, sizes[b]) = jacobians[b];
    }
    H_ += w * J.transpose() * J;
    g_ += w * J.transpose() * r;
  }

  // The Schur complement on the last 6 columns (delta).
  void MarginalizePoints(Eigen::Matrix<double, 6, 6>* H, Eigen::Matrix<double, 6, 1>* g) const {
    const int p = n_ - 6;
    *H = H_.bottomRightCorner<6, 6>();
    *g = g_.tail<6>();
    if (p == 0) return;
    Eigen::MatrixXd H_pp = H_.topLeftCorner(p, p);
    H_pp.diagonal().array() += kPointDamping;
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(H_pp);
    const Eigen::MatrixXd H_pe = H_.topRightCorner(p, 6);
    *H -= H_pe.transpose() * ldlt.solve(H_pe);
    *g -= H_pe.transpose() * ldlt.solve(g_.head(p));
  }

 private:
  int n_;
  Eigen::MatrixXd H_;
  Eigen::VectorXd g_;
};

}  // namespace

ExtrinsicFactor MarginalizeIntoExtrinsic(const PinholeCamera& camera, const ExtrinsicPrior& chart,
                                         const Eigen::Isometry3d& T_base_cam,
                                         const MarginalizationInput& input, double pixel_sigma_px,
                                         double huber_scale) {
  ExtrinsicFactor factor;
  factor.delta_lin = chart.DeltaOf(T_base_cam);
  const int n = static_cast<int>(input.points.size());
  if (n == 0 || input.corners.empty()) return factor;
  NormalEquations normal(n);
  const int delta_offset = 3 * n;
  const double* delta = factor.delta_lin.data();
  const double inv_sigma = 1.0 / pixel_sigma_px;
  for (const MarginalizationInput::Corner& c : input.corners) {
    const Eigen::Matrix2d W = c.sqrt_information.isZero()
                                  ? Eigen::Matrix2d(Eigen::Matrix2d::Identity() * inv_sigma)
                                  : c.sqrt_information;
    ceres::AutoDiffCostFunction<CornerInChart, 2, 3, 6> cost(
        new CornerInChart{camera, c.uv, W, Pose(c.T_map_base), chart.q0(), chart.t0()});
    normal.Add(cost, {3 * c.point, delta_offset}, {input.points[c.point].data(), delta},
               huber_scale);
  }
  for (const MarginalizationInput::RoadPrior& prior : input.road_priors) {
    std::unique_ptr<ceres::CostFunction> cost(
        residuals::RoadSurfacePriorResidual::Create(prior.plane, prior.sigma_m));
    normal.Add(*cost, {3 * prior.point}, {input.points[prior.point].data()}, 0.0);
  }
  normal.MarginalizePoints(&factor.H, &factor.g);
  return factor;
}

}  // namespace ipm_road_mapper
