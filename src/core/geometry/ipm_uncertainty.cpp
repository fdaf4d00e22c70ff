#include "ipm_road_mapper/core/geometry/ipm_uncertainty.h"

#include <ceres/jet.h>

#include <algorithm>
#include <cmath>

#include "ipm_road_mapper/core/geometry/ipm.h"

namespace ipm_road_mapper {
namespace {

// f(uv, theta, h) for any scalar type: pitch the camera by theta about base_link's y axis
// (R' = Ry(theta) R_base_cam, the camera center stays) and raise it by h.
template <typename T>
bool GroundPointWithPerturbation(const PinholeCamera& camera, const Eigen::Isometry3d& T_base_cam,
                                 const Eigen::Matrix<T, 2, 1>& uv, const T& theta, const T& h,
                                 Eigen::Matrix<T, 3, 1>* p_base) {
  using std::cos;
  using std::sin;
  Eigen::Matrix<T, 3, 3> Ry;
  const T c = cos(theta), s = sin(theta);
  Ry << c, T(0.0), s, T(0.0), T(1.0), T(0.0), -s, T(0.0), c;
  const Eigen::Matrix<T, 3, 3> R = Ry * T_base_cam.linear().cast<T>();
  Eigen::Matrix<T, 3, 1> t = T_base_cam.translation().cast<T>();
  t(2) += h;
  return Ipm::GroundPoint<T>(camera, R, t, uv, p_base);
}

}  // namespace

bool PerturbedGroundPoint(const PinholeCamera& camera, const Eigen::Isometry3d& T_base_cam,
                          const Eigen::Vector2d& uv, double theta, double h,
                          Eigen::Vector3d* p_base) {
  return GroundPointWithPerturbation<double>(camera, T_base_cam, uv, theta, h, p_base);
}

std::optional<IpmUncertainty> ComputeIpmUncertainty(const PinholeCamera& camera,
                                                    const Eigen::Isometry3d& T_base_cam,
                                                    const Eigen::Vector2d& uv,
                                                    const IpmErrorModel& model) {
  // Four inputs: u, v, theta, h; one forward pass gives all Jacobian columns.
  using Jet = ceres::Jet<double, 4>;
  const Eigen::Matrix<Jet, 2, 1> uv_jet(Jet(uv.x(), 0), Jet(uv.y(), 1));
  const Jet theta(0.0, 2);
  const Jet h(0.0, 3);
  Eigen::Matrix<Jet, 3, 1> p;
  if (!GroundPointWithPerturbation<Jet>(camera, T_base_cam, uv_jet, theta, h, &p)) {
    return std::nullopt;
  }
  IpmUncertainty result;
  for (int r = 0; r < 3; ++r) {
    result.p_base(r) = p(r).a;
    result.J_uv(r, 0) = p(r).v(0);
    result.J_uv(r, 1) = p(r).v(1);
    result.J_theta(r) = p(r).v(2);
    result.J_h(r) = p(r).v(3);
  }
  const Eigen::Vector3d pixel_term = result.J_uv * model.pixel_error_px;
  result.omega =
      pixel_term * pixel_term.transpose() +
      model.pitch_sigma_rad * model.pitch_sigma_rad * result.J_theta * result.J_theta.transpose() +
      model.height_sigma_m * model.height_sigma_m * result.J_h * result.J_h.transpose();
  result.score = result.omega.trace();
  return result;
}

std::vector<std::size_t> SelectLowestScores(const std::vector<double>& scores, std::size_t n) {
  std::vector<std::size_t> order;
  order.reserve(scores.size());
  for (std::size_t i = 0; i < scores.size(); ++i) {
    if (std::isfinite(scores[i])) order.push_back(i);
  }
  std::stable_sort(order.begin(), order.end(),
                   [&scores](std::size_t a, std::size_t b) { return scores[a] < scores[b]; });
  if (order.size() > n) order.resize(n);
  return order;
}

}  // namespace ipm_road_mapper
