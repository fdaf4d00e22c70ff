#include "ipm_road_mapper/core/mapper/frame_index.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "ipm_road_mapper/core/geometry/grid_cell.h"

namespace ipm_road_mapper {

FrameIndex::FrameIndex(double cell_size_m) : cell_size_m_(cell_size_m) {
  if (!(cell_size_m > 0.0)) throw std::invalid_argument("FrameIndex: cell size must be > 0");
}

std::int64_t FrameIndex::Cell(double v) const { return GridCell(v, cell_size_m_); }

FrameIndex::Key FrameIndex::KeyOf(std::int64_t ix, std::int64_t iy) {
  // Cells within +-2^31 of the origin: that many cells of a meter or more cover any drive.
  return static_cast<Key>((static_cast<std::uint64_t>(ix) << 32) ^
                          (static_cast<std::uint64_t>(iy) & 0xffffffffULL));
}

double FrameIndex::Distance(std::size_t index, const Eigen::Vector3d& p_map) const {
  return (positions_[index] - p_map.head<2>()).norm();
}

void FrameIndex::Set(std::size_t index, const Eigen::Vector3d& p_map) {
  if (index > positions_.size()) throw std::out_of_range("FrameIndex::Set: index skips frames");
  const std::int64_t ix = Cell(p_map.x()), iy = Cell(p_map.y());
  if (index < positions_.size()) {
    const Eigen::Vector2d& old = positions_[index];
    const Key from = KeyOf(Cell(old.x()), Cell(old.y()));
    positions_[index] = p_map.head<2>();
    if (from == KeyOf(ix, iy)) return;
    std::vector<std::size_t>& cell = cells_[from];
    cell.erase(std::lower_bound(cell.begin(), cell.end(), index));
    if (cell.empty()) cells_.erase(from);
  } else {
    positions_.push_back(p_map.head<2>());
  }
  std::vector<std::size_t>& cell = cells_[KeyOf(ix, iy)];
  cell.insert(std::upper_bound(cell.begin(), cell.end(), index), index);
  if (max_ix_ < min_ix_) {
    min_ix_ = max_ix_ = ix;
    min_iy_ = max_iy_ = iy;
  } else {
    min_ix_ = std::min(min_ix_, ix);
    max_ix_ = std::max(max_ix_, ix);
    min_iy_ = std::min(min_iy_, iy);
    max_iy_ = std::max(max_iy_, iy);
  }
}

void FrameIndex::Clear() {
  positions_.clear();
  cells_.clear();
  min_ix_ = min_iy_ = 0;
  max_ix_ = max_iy_ = -1;
}

template <typename F>
void FrameIndex::ForRing(std::int64_t ix, std::int64_t iy, std::int64_t ring, F f) const {
  auto cell = [&](std::int64_t cx, std::int64_t cy) {
    auto it = cells_.find(KeyOf(cx, cy));
    if (it == cells_.end()) return;
    for (std::size_t i : it->second) f(i);
  };
  if (ring == 0) {
    cell(ix, iy);
    return;
  }
  for (std::int64_t d = -ring; d <= ring; ++d) {
    cell(ix + d, iy - ring);
    cell(ix + d, iy + ring);
  }
  for (std::int64_t d = -ring + 1; d <= ring - 1; ++d) {
    cell(ix - ring, iy + d);
    cell(ix + ring, iy + d);
  }
}

std::vector<std::size_t> FrameIndex::Within(const Eigen::Vector3d& p_map, double radius_m) const {
  std::vector<std::size_t> out;
  if (positions_.empty() || !(radius_m >= 0.0)) return out;
  const std::int64_t x0 = std::max(Cell(p_map.x() - radius_m), min_ix_);
  const std::int64_t x1 = std::min(Cell(p_map.x() + radius_m), max_ix_);
  const std::int64_t y0 = std::max(Cell(p_map.y() - radius_m), min_iy_);
  const std::int64_t y1 = std::min(Cell(p_map.y() + radius_m), max_iy_);
  for (std::int64_t ix = x0; ix <= x1; ++ix) {
    for (std::int64_t iy = y0; iy <= y1; ++iy) {
      auto it = cells_.find(KeyOf(ix, iy));
      if (it == cells_.end()) continue;
      for (std::size_t i : it->second) {
        if (Distance(i, p_map) <= radius_m) out.push_back(i);
      }
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

bool FrameIndex::Nearest(const Eigen::Vector3d& p_map, std::size_t* index,
                         double* distance_m) const {
  if (positions_.empty()) return false;
  const std::int64_t ix = Cell(p_map.x()), iy = Cell(p_map.y());
  const std::int64_t max_ring = std::max({std::abs(ix - min_ix_), std::abs(ix - max_ix_),
                                          std::abs(iy - min_iy_), std::abs(iy - max_iy_)});
  double best = std::numeric_limits<double>::infinity();
  std::size_t best_index = 0;
  for (std::int64_t ring = 0; ring <= max_ring; ++ring) {
    // Every point of ring r >= 1 is at least (r - 1) cells from p_map.
    if (ring >= 1 && static_cast<double>(ring - 1) * cell_size_m_ > best) break;
    ForRing(ix, iy, ring, [&](std::size_t i) {
      const double d = Distance(i, p_map);
      if (d < best || (d == best && i < best_index)) {
        best = d;
        best_index = i;
      }
    });
  }
  *index = best_index;
  *distance_m = best;
  return true;
}

}  // namespace ipm_road_mapper
