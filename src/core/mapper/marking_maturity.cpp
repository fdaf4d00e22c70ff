#include "ipm_road_mapper/core/mapper/marking_maturity.h"

#include <algorithm>

namespace ipm_road_mapper {

bool SeenUpClose(const MarkingElement& m) {
  for (const MarkingMeasurement& meas : m.history) {
    const Eigen::Vector3d center = 0.25 * (meas.corners_base[0] + meas.corners_base[1] +
                                           meas.corners_base[2] + meas.corners_base[3]);
    if (center.head<2>().norm() <= kMatureRangeM) return true;
  }
  return false;
}

bool SeenOnlyInPartialViews(const MarkingElement& m) {
  return std::none_of(m.history.begin(), m.history.end(),
                      [](const MarkingMeasurement& meas) { return meas.Complete(); });
}

}  // namespace ipm_road_mapper
