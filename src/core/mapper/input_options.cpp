#include "ipm_road_mapper/core/mapper/input_options.h"

#include <cmath>
#include <vector>

#include "ipm_road_mapper/core/geometry/rigid_transform.h"

namespace ipm_road_mapper {

InputOptions LoadInputOptions(OptionsReader reader) {
  InputOptions o;
  auto non_empty = [](const std::string& v) -> std::string {
    return v.empty() ? "must not be empty" : "";
  };
  reader.Read<std::string>("base_frame", &o.base_frame, non_empty);
  if (reader.Has("extrinsic")) {
    OptionsReader extrinsic = reader.Child("extrinsic");
    auto three_finite = [](const std::vector<double>& v) -> std::string {
      if (v.size() != 3) return "must have 3 values";
      for (double x : v) {
        if (!std::isfinite(x)) return "must be finite";
      }
      return "";
    };
    std::vector<double> xyz, rpy_deg;
    extrinsic.ReadRequired<std::vector<double>>("xyz", &xyz, three_finite);
    extrinsic.ReadRequired<std::vector<double>>("rpy_deg", &rpy_deg, three_finite);
    extrinsic.RejectUnknownKeys();
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    const double k = M_PI / 180.0;
    T.linear() = RotationFromRpy(rpy_deg[0] * k, rpy_deg[1] * k, rpy_deg[2] * k);
    T.translation() = Eigen::Vector3d(xyz[0], xyz[1], xyz[2]);
    o.T_base_cam = T;
  } else {
    reader.Child("extrinsic");  // marks the optional key as known
  }
  reader.RejectUnknownKeys();
  return o;
}

}  // namespace ipm_road_mapper
