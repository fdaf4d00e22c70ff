#include "ipm_road_mapper/core/mapper/map_store.h"

#include <algorithm>
#include <cmath>

#include "ipm_road_mapper/core/geometry/catmull_rom_spline.h"
#include "ipm_road_mapper/core/mapper/odometry_correction.h"

namespace ipm_road_mapper {

MapStore::MapStore(double road_plane_radius_m)
    : road_plane_radius_m_(road_plane_radius_m),
      // Cells of the radius: a query looks at 3x3 cells at most.
      frame_index_(road_plane_radius_m > 0.0 ? road_plane_radius_m : 1.0) {}

const FrameRecord& MapStore::AddFrame(double stamp, const Eigen::Isometry3d& T_map_base_odom,
                                      const RoadPlane& ground_base) {
  FrameRecord frame;
  frame.index = map_.frames.size();
  frame.stamp = stamp;
  frame.T_map_base_odom = T_map_base_odom;
  frame.T_map_base = T_map_base_odom;
  frame.ground_base = ground_base;
  frame_index_.Set(frame.index, frame.T_map_base.translation());
  map_.frames.push_back(frame);
  return map_.frames.back();
}

void MapStore::SetFramePose(std::size_t index, const Eigen::Isometry3d& T_map_base) {
  map_.frames[index].T_map_base = T_map_base;
  frame_index_.Set(index, T_map_base.translation());
}

void MapStore::SetCorrectionFrom(const std::vector<std::size_t>& solved) {
  if (solved.empty()) return;
  T_map_odom_ = FitOdometryCorrection(map_.frames, solved);
  corrected_frame_ = static_cast<std::int64_t>(*std::max_element(solved.begin(), solved.end()));
}

Eigen::Isometry3d MapStore::CorrectedPose(std::size_t index) const {
  const FrameRecord& frame = map_.frames[index];
  if (static_cast<std::int64_t>(index) <= corrected_frame_) return frame.T_map_base;
  return T_map_odom_ * frame.T_map_base_odom;
}

namespace {

// Erases the measurements of frames before `frame` (histories are sorted by frame).
template <typename Element>
void PruneBefore(std::size_t frame, Element* e) {
  auto keep = std::lower_bound(
      e->history.begin(), e->history.end(), frame,
      [](const auto& measurement, std::size_t f) { return measurement.frame_index < f; });
  const std::size_t n = static_cast<std::size_t>(keep - e->history.begin());
  if (n == 0) return;
  e->history.erase(e->history.begin(), keep);
  e->history.shrink_to_fit();
  e->pruned += n;
}

// The key of integer cell (ix, iy).
std::int64_t CellKeyOf(std::int64_t ix, std::int64_t iy) {
  return static_cast<std::int64_t>((static_cast<std::uint64_t>(ix) << 32) ^
                                   (static_cast<std::uint64_t>(iy) & 0xffffffffULL));
}

std::int64_t CellIndexOf(double coordinate, double cell_m) {
  return static_cast<std::int64_t>(std::floor(coordinate / cell_m));
}

}  // namespace

MapStore::CellKey MapStore::RetiredCellOf(const Eigen::Vector3d& p_map) const {
  return CellKeyOf(CellIndexOf(p_map.x(), kRetiredCellM), CellIndexOf(p_map.y(), kRetiredCellM));
}

void MapStore::IndexLane(const LaneElement& lane, std::size_t first_changed) {
  const std::vector<Eigen::Vector3d>& cps = lane.control_points_map;
  auto note = [&](const Eigen::Vector2d& p) {
    if (!p.allFinite()) return;
    std::vector<std::uint64_t>& ids =
        lane_cells_[CellKeyOf(CellIndexOf(p.x(), kLaneCellM), CellIndexOf(p.y(), kLaneCellM))];
    if (std::find(ids.begin(), ids.end(), lane.id) == ids.end()) ids.push_back(lane.id);
  };
  // Each segment from the point before the first changed one, sampled at half a cell, so
  // that a long segment (a join's bridge) lists the cells it crosses.
  const std::size_t from = first_changed > 0 ? first_changed - 1 : 0;
  for (std::size_t j = from; j < cps.size(); ++j) {
    note(cps[j].head<2>());
    if (j + 1 == cps.size()) break;
    const Eigen::Vector2d d = (cps[j + 1] - cps[j]).head<2>();
    const int steps = static_cast<int>(std::min(1e4, std::floor(d.norm() / (0.5 * kLaneCellM))));
    for (int k = 1; k <= steps; ++k) note(cps[j].head<2>() + d * (k / (steps + 1.0)));
  }
}

std::vector<std::size_t> MapStore::LanesNear(const Eigen::Vector3d& p_map, double radius_m) const {
  std::vector<std::size_t> out;
  if (map_.lanes.empty() || !(radius_m >= 0.0) || !p_map.allFinite()) return out;
  const std::int64_t x0 = CellIndexOf(p_map.x() - radius_m, kLaneCellM);
  const std::int64_t x1 = CellIndexOf(p_map.x() + radius_m, kLaneCellM);
  const std::int64_t y0 = CellIndexOf(p_map.y() - radius_m, kLaneCellM);
  const std::int64_t y1 = CellIndexOf(p_map.y() + radius_m, kLaneCellM);
  // A disc of more cells than the index holds and than a query should visit (a huge
  // radius): every lane, cheaper than its cells.
  const double cells = (static_cast<double>(x1 - x0) + 1.0) * (static_cast<double>(y1 - y0) + 1.0);
  if (!(cells <= std::max(kMaxLaneQueryCells, static_cast<double>(lane_cells_.size())))) {
    out.resize(map_.lanes.size());
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = i;
    return out;
  }
  bool rebuilt = false;
  auto index_of = [&](std::uint64_t id, std::size_t* index) {
    auto it = lane_index_by_id_.find(id);
    if ((it == lane_index_by_id_.end() || it->second >= map_.lanes.size() ||
         map_.lanes[it->second].id != id) &&
        !rebuilt) {
      lane_index_by_id_.clear();
      for (std::size_t i = 0; i < map_.lanes.size(); ++i) lane_index_by_id_[map_.lanes[i].id] = i;
      rebuilt = true;
      it = lane_index_by_id_.find(id);
    }
    if (it == lane_index_by_id_.end() || map_.lanes[it->second].id != id) return false;
    *index = it->second;
    return true;
  };
  for (std::int64_t ix = x0; ix <= x1; ++ix) {
    for (std::int64_t iy = y0; iy <= y1; ++iy) {
      auto cell = lane_cells_.find(CellKeyOf(ix, iy));
      if (cell == lane_cells_.end()) continue;
      std::vector<std::uint64_t>& ids = cell->second;
      for (std::size_t k = 0; k < ids.size();) {
        std::size_t index = 0;
        if (index_of(ids[k], &index)) {
          out.push_back(index);
          ++k;
        } else {
          ids.erase(ids.begin() + static_cast<std::ptrdiff_t>(k));  // the lane left the map
        }
      }
    }
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

void MapStore::IndexRetired(std::size_t retired_index) {
  const MarkingElement& m = map_.retired_markings[retired_index];
  retired_cells_[RetiredCellOf(m.Center())].push_back(retired_index);
  retired_index_by_id_[m.id] = retired_index;
  max_retired_cov_trace_ = std::max(max_retired_cov_trace_, m.center_cov_map.trace());
}

void MapStore::RetireMarkings(std::size_t first_frame) {
  std::vector<MarkingElement>& live = map_.markings;
  std::size_t kept = 0;
  for (std::size_t i = 0; i < live.size(); ++i) {
    if (live[i].retired && live[i].last_frame < first_frame) {
      map_.retired_markings.push_back(std::move(live[i]));
      IndexRetired(map_.retired_markings.size() - 1);
      Touch(&map_.retired_markings.back());  // its place in the export changed
    } else {
      if (kept != i) live[kept] = std::move(live[i]);
      ++kept;
    }
  }
  live.resize(kept);
}

std::size_t MapStore::ReviveMarking(std::size_t retired_index) {
  std::vector<MarkingElement>& retired = map_.retired_markings;
  map_.markings.push_back(std::move(retired[retired_index]));
  noted_marking_ids_.insert(map_.markings.back().id);  // in the map: its removal is news
  if (retired_index + 1 != retired.size()) {
    retired[retired_index] = std::move(retired.back());
    changes_.NoteRetiredMoved(retired_index);  // an export's order there changed
  }
  retired.pop_back();
  ReindexRetiredMarkings();
  return map_.markings.size() - 1;
}

void MapStore::ReindexRetiredMarkings() {
  retired_cells_.clear();
  retired_index_by_id_.clear();
  max_retired_cov_trace_ = 0.0;
  for (std::size_t i = 0; i < map_.retired_markings.size(); ++i) IndexRetired(i);
}

std::vector<std::size_t> MapStore::RetiredMarkingsNear(const Eigen::Vector3d& p_map,
                                                       double radius_m) const {
  std::vector<std::size_t> out;
  if (map_.retired_markings.empty() || !(radius_m >= 0.0) || !p_map.allFinite()) return out;
  const auto x0 = static_cast<std::int64_t>(std::floor((p_map.x() - radius_m) / kRetiredCellM));
  const auto x1 = static_cast<std::int64_t>(std::floor((p_map.x() + radius_m) / kRetiredCellM));
  const auto y0 = static_cast<std::int64_t>(std::floor((p_map.y() - radius_m) / kRetiredCellM));
  const auto y1 = static_cast<std::int64_t>(std::floor((p_map.y() + radius_m) / kRetiredCellM));
  auto within = [&](std::size_t i) {
    return (map_.retired_markings[i].Center() - p_map).head<2>().norm() <= radius_m;
  };
  // A disc wider than the map (a huge covariance): a scan is cheaper than its cells.
  const double cells = (static_cast<double>(x1 - x0) + 1.0) * (static_cast<double>(y1 - y0) + 1.0);
  if (!(cells <= static_cast<double>(map_.retired_markings.size()))) {
    for (std::size_t i = 0; i < map_.retired_markings.size(); ++i) {
      if (within(i)) out.push_back(i);
    }
    return out;
  }
  for (std::int64_t ix = x0; ix <= x1; ++ix) {
    for (std::int64_t iy = y0; iy <= y1; ++iy) {
      const Eigen::Vector3d cell_point((ix + 0.5) * kRetiredCellM, (iy + 0.5) * kRetiredCellM, 0.0);
      auto it = retired_cells_.find(RetiredCellOf(cell_point));
      if (it == retired_cells_.end()) continue;
      for (std::size_t i : it->second) {
        if (within(i)) out.push_back(i);
      }
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

void MapStore::PruneHistoriesBefore(std::size_t frame) {
  for (MarkingElement& m : map_.markings) PruneBefore(frame, &m);
  for (MarkingElement& m : map_.retired_markings) PruneBefore(frame, &m);
  for (LaneElement& l : map_.lanes) PruneBefore(frame, &l);
}

void MapStore::Clear() {
  const std::uint64_t next_id = map_.next_id;
  map_ = RoadMap();
  map_.next_id = next_id;
  frame_index_.Clear();
  retired_cells_.clear();
  retired_index_by_id_.clear();
  lane_cells_.clear();
  lane_index_by_id_.clear();
  noted_marking_ids_.clear();
  noted_lane_ids_.clear();
  changes_.Clear();
  max_retired_cov_trace_ = 0.0;
  T_map_odom_ = Eigen::Isometry3d::Identity();
  corrected_frame_ = -1;
}

bool MapStore::IsRetired(const MarkingElement* marking) const {
  const std::vector<MarkingElement>& retired = map_.retired_markings;
  return !retired.empty() && marking >= retired.data() && marking < retired.data() + retired.size();
}

void MapStore::Touch(MarkingElement* marking) {
  marking->revision = changes_.Next();
  if (IsRetired(marking)) changes_.NoteRetired(marking->revision, marking->id);
}

void MapStore::Touch(LaneElement* lane, std::size_t first_changed) {
  lane->revision = changes_.Next();
  if (!lane->exported_at && lane->Exported()) lane->exported_at = lane->revision;
  changes_.NoteLane(lane->revision, lane->id, first_changed);
  IndexLane(*lane, first_changed);
}

std::int64_t MapStore::RetiredIndexOf(std::uint64_t id) const {
  const auto it = retired_index_by_id_.find(id);
  return it == retired_index_by_id_.end() ? -1 : static_cast<std::int64_t>(it->second);
}

void MapStore::NoteRemovals() {
  std::unordered_set<std::uint64_t> markings, lanes;
  markings.reserve(map_.markings.size());
  for (const MarkingElement& m : map_.markings) markings.insert(m.id);
  for (const LaneElement& l : map_.lanes) lanes.insert(l.id);
  // A marking that went from live to retired is still in the map.
  for (std::uint64_t id : noted_marking_ids_) {
    if (!markings.count(id) && !retired_index_by_id_.count(id)) {
      changes_.NoteRemoved(ElementKind::kMarking, id);
    }
  }
  for (std::uint64_t id : noted_lane_ids_) {
    if (!lanes.count(id)) changes_.NoteRemoved(ElementKind::kLane, id);
  }
  noted_marking_ids_ = std::move(markings);
  noted_lane_ids_ = std::move(lanes);
}

Eigen::Vector3d MapStore::RoadDirectionAt(const Eigen::Vector3d& p_map) const {
  double best = kRoadDirectionMaxDistanceM;
  Eigen::Vector3d tangent_map = Eigen::Vector3d::Zero();
  // ControlPointRangeNear's box about p_map, of half side max + 5 m: its corners bound it.
  for (std::size_t i : LanesNear(p_map, std::sqrt(2.0) * (kRoadDirectionMaxDistanceM + 5.0))) {
    const LaneElement& lane = map_.lanes[i];
    std::size_t first = 0, last = 0;  // the lane's part near p_map only
    if (!ControlPointRangeNear(lane.control_points_map, {p_map}, kRoadDirectionMaxDistanceM + 5.0,
                               &first, &last)) {
      continue;
    }
    const CatmullRomSpline spline(std::vector<Eigen::Vector3d>(
        lane.control_points_map.begin() + first, lane.control_points_map.begin() + last + 1));
    const CatmullRomSpline::ClosestPoint closest = spline.FindClosest(p_map);
    if (closest.distance_m >= best) continue;
    best = closest.distance_m;
    tangent_map = spline.Derivative(closest.s);
  }
  return tangent_map.norm() > 0.0 ? tangent_map.normalized() : tangent_map;
}

RoadSurfaceEstimate MapStore::RoadSurfaceAt(const Eigen::Vector3d& p_map) const {
  std::size_t closest = 0;
  double closest_distance_m = 0.0;
  if (!frame_index_.Nearest(p_map, &closest, &closest_distance_m)) return RoadSurfaceEstimate();
  std::vector<const Eigen::Isometry3d*> within;
  std::vector<std::size_t> indices = frame_index_.Within(p_map, road_plane_radius_m_);
  if (indices.empty()) {
    // Aside or ahead of every pose: the road around the closest one (map_store.h).
    indices =
        frame_index_.Within(map_.frames[closest].T_map_base.translation(), road_plane_radius_m_);
  }
  for (std::size_t i : indices) within.push_back(&map_.frames[i].T_map_base);
  return RoadSurfaceFromPoses(within, map_.frames[closest].T_map_base, closest_distance_m, p_map);
}

}  // namespace ipm_road_mapper
