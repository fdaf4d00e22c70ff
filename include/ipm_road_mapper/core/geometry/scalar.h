// The double value of a scalar that is either a double or a ceres::Jet, so templated
// geometry can branch or iterate on values without including Ceres.
#pragma once

namespace ipm_road_mapper {

inline double ScalarValue(double x) { return x; }

template <typename JetT>
double ScalarValue(const JetT& x) {
  return x.a;
}

}  // namespace ipm_road_mapper
