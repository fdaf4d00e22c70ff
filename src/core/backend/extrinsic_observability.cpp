#include "ipm_road_mapper/core/backend/extrinsic_observability.h"

#include <ceres/crs_matrix.h>

#include <Eigen/Eigenvalues>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>

namespace ipm_road_mapper {
namespace {

// Damping of the marginalized blocks before their inversion: a block the measurements see
// from too few directions must not blow up the Schur complement (as in
// extrinsic_marginalization.cpp).
constexpr double kDamping = 1e-6;

}  // namespace

std::string ObservedAxesText(const std::array<bool, 6>& observed) {
  static const char* const kAxes[6] = {"roll", "pitch", "yaw", "x", "y", "z"};
  std::string text;
  for (int i = 0; i < 6; ++i) {
    if (!observed[i]) continue;
    if (!text.empty()) text += " ";
    text += kAxes[i];
  }
  return text.empty() ? "none" : text;
}

Vector6d PriorSigma(const Eigen::Vector3d& sigma_rot_rad, const Eigen::Vector3d& sigma_trans_m) {
  Vector6d sigma;
  sigma << sigma_rot_rad, sigma_trans_m;
  return sigma;
}

Matrix6d ExtrinsicObservability::ObservedInformation() const {
  const Vector6d s_inv = prior_sigma.cwiseInverse();
  Matrix6d H_w = Matrix6d::Zero();
  for (int k = 0; k < 6; ++k) {
    if (!observed[k]) continue;
    H_w += eigenvalues(k) * basis_whitened.col(k) * basis_whitened.col(k).transpose();
  }
  return s_inv.asDiagonal() * H_w * s_inv.asDiagonal();
}

Matrix6d ExtrinsicObservability::UnobservedHoldSqrtInformation(double weight) const {
  Matrix6d L = Matrix6d::Zero();
  const double root = std::sqrt(weight);
  for (int k = 0; k < 6; ++k) {
    if (observed[k]) continue;
    L.row(k) = root * basis_whitened.col(k).transpose() * prior_sigma.cwiseInverse().asDiagonal();
  }
  return L;
}

ExtrinsicObservability AnalyzeObservability(const Matrix6d& information,
                                            const Vector6d& prior_sigma,
                                            double min_information_ratio) {
  ExtrinsicObservability o;
  o.information = 0.5 * (information + information.transpose());
  o.prior_sigma = prior_sigma;
  const Matrix6d H_w = prior_sigma.asDiagonal() * o.information * prior_sigma.asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Matrix6d> eigen(H_w);
  o.eigenvalues = eigen.eigenvalues().cwiseMax(0.0);
  o.basis_whitened = eigen.eigenvectors();
  for (int k = 0; k < 6; ++k) o.observed[k] = o.eigenvalues(k) >= min_information_ratio;
  o.CountObserved();
  return o;
}

void ExtrinsicObservability::CountObserved() {
  rank = 0;
  Eigen::Matrix<double, 6, Eigen::Dynamic> V_observed(6, 0);
  for (int k = 0; k < 6; ++k) {
    if (!observed[k]) continue;
    ++rank;
    V_observed.conservativeResize(6, V_observed.cols() + 1);
    V_observed.col(V_observed.cols() - 1) = basis_whitened.col(k);
  }
  for (int i = 0; i < 6; ++i) {
    axis_observed[i] = rank > 0 && V_observed.row(i).squaredNorm() >= 0.5;
  }
}

Matrix6d ExtrinsicInformation(ceres::Problem* problem, double* q_base_cam, double* t_base_cam,
                              const std::vector<ceres::ResidualBlockId>& excluded) {
  if (!problem->HasParameterBlock(q_base_cam) || !problem->HasParameterBlock(t_base_cam) ||
      problem->IsParameterBlockConstant(q_base_cam) ||
      problem->IsParameterBlockConstant(t_base_cam) ||
      problem->ParameterBlockTangentSize(q_base_cam) != 3) {
    return Matrix6d::Zero();
  }
  std::vector<double*> blocks;
  problem->GetParameterBlocks(&blocks);
  std::vector<double*> order;  // every other variable block first, the extrinsic last
  for (double* block : blocks) {
    if (block == q_base_cam || block == t_base_cam || problem->IsParameterBlockConstant(block)) {
      continue;
    }
    if (problem->ParameterBlockTangentSize(block) > 0) order.push_back(block);
  }
  order.push_back(q_base_cam);
  order.push_back(t_base_cam);
  std::vector<ceres::ResidualBlockId> residuals;
  problem->GetResidualBlocks(&residuals);
  residuals.erase(std::remove_if(residuals.begin(), residuals.end(),
                                 [&](ceres::ResidualBlockId id) {
                                   return std::find(excluded.begin(), excluded.end(), id) !=
                                          excluded.end();
                                 }),
                  residuals.end());
  if (residuals.empty()) return Matrix6d::Zero();
  ceres::Problem::EvaluateOptions evaluate;
  evaluate.parameter_blocks = order;
  evaluate.residual_blocks = residuals;
  evaluate.apply_loss_function = true;
  ceres::CRSMatrix crs;
  if (!problem->Evaluate(evaluate, nullptr, nullptr, nullptr, &crs)) return Matrix6d::Zero();
  const Eigen::Map<const Eigen::SparseMatrix<double, Eigen::RowMajor, int>> J(
      crs.num_rows, crs.num_cols, static_cast<int>(crs.values.size()), crs.rows.data(),
      crs.cols.data(), crs.values.data());
  const Eigen::SparseMatrix<double> H = Eigen::SparseMatrix<double>(J.transpose()) * J;
  const int p = crs.num_cols - 6;
  Matrix6d S = Matrix6d(H.block(p, p, 6, 6));
  if (p > 0) {
    Eigen::SparseMatrix<double> H_pp = H.block(0, 0, p, p);
    Eigen::SparseMatrix<double> damping(p, p);
    damping.setIdentity();
    H_pp += kDamping * damping;
    const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(H_pp);
    if (ldlt.info() != Eigen::Success) return Matrix6d::Zero();
    const Eigen::MatrixXd H_pe = Eigen::MatrixXd(H.block(0, p, p, 6));
    S -= H_pe.transpose() * ldlt.solve(H_pe);
  }
  // ceres::EigenQuaternionManifold: q + d = [cos|d|, sin|d| d/|d|] q, a rotation by 2|d|
  // about d in base_link; the chart's phi = 2 d, so H_phi = H_d / 4 (rotation rows/cols / 2).
  Vector6d D;
  D << 0.5, 0.5, 0.5, 1.0, 1.0, 1.0;
  return D.asDiagonal() * (0.5 * (S + S.transpose())) * D.asDiagonal();
}

}  // namespace ipm_road_mapper
