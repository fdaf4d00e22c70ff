#include "ipm_road_mapper/sim/instance_split.h"

#include <cstdint>

namespace ipm_road_mapper {
namespace sim {

int SplitInstance(int value, int new_value, const Eigen::Vector2d& normal, cv::Mat* mask) {
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  int count = 0;
  for (int r = 0; r < mask->rows; ++r) {
    const std::uint16_t* row = mask->ptr<std::uint16_t>(r);
    for (int c = 0; c < mask->cols; ++c) {
      if (row[c] == value) {
        sum += Eigen::Vector2d(c, r);
        ++count;
      }
    }
  }
  if (count == 0) return 0;
  const Eigen::Vector2d centroid = sum / count;
  int relabelled = 0;
  for (int r = 0; r < mask->rows; ++r) {
    std::uint16_t* row = mask->ptr<std::uint16_t>(r);
    for (int c = 0; c < mask->cols; ++c) {
      if (row[c] == value && (Eigen::Vector2d(c, r) - centroid).dot(normal) > 0.0) {
        row[c] = static_cast<std::uint16_t>(new_value);
        ++relabelled;
      }
    }
  }
  return relabelled;
}

}  // namespace sim
}  // namespace ipm_road_mapper
