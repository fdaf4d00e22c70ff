// A spatial index over the frames' positions (x-y): a uniform grid of cells about as large
// as the road-plane radius, so that "the frames within r of p" and "the frame nearest to p"
// look at a few cells instead of every frame of the drive. Positions move when the back end
// corrects poses; Set keeps the index in step.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <vector>

namespace ipm_road_mapper {

class FrameIndex {
 public:
  // `cell_size_m` > 0: the grid's cell side.
  explicit FrameIndex(double cell_size_m);

  // Puts frame `index` at p_map (x-y used): a new frame when index == size(), else a move.
  void Set(std::size_t index, const Eigen::Vector3d& p_map);
  void Clear();
  std::size_t size() const { return positions_.size(); }

  // The frames within radius_m of p_map (horizontal distance <= radius_m), sorted by index.
  std::vector<std::size_t> Within(const Eigen::Vector3d& p_map, double radius_m) const;
  // The frame nearest to p_map (the lowest index among equally near ones) and its horizontal
  // distance; false when the index is empty.
  bool Nearest(const Eigen::Vector3d& p_map, std::size_t* index, double* distance_m) const;

 private:
  using Key = std::int64_t;
  static Key KeyOf(std::int64_t ix, std::int64_t iy);
  std::int64_t Cell(double v) const;
  double Distance(std::size_t index, const Eigen::Vector3d& p_map) const;
  // Applies f to every frame in the cells of the square ring `ring` around cell (ix, iy).
  template <typename F>
  void ForRing(std::int64_t ix, std::int64_t iy, std::int64_t ring, F f) const;

  double cell_size_m_;
  std::vector<Eigen::Vector2d> positions_;  // by frame index
  std::unordered_map<Key, std::vector<std::size_t>> cells_;
  std::int64_t min_ix_ = 0, max_ix_ = -1, min_iy_ = 0, max_iy_ = -1;  // bounds ever occupied
};

}  // namespace ipm_road_mapper
