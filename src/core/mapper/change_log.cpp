#include "ipm_road_mapper/core/mapper/change_log.h"

#include <algorithm>

namespace ipm_road_mapper {

void ChangeLog::NoteRetired(std::uint64_t revision, std::uint64_t id) {
  retired_.emplace_back(revision, id);
}

void ChangeLog::NoteLane(std::uint64_t revision, std::uint64_t id, std::size_t first_changed) {
  std::vector<Entry>& log = lane_changes_[id];
  while (!log.empty() && log.back().second >= first_changed) log.pop_back();
  log.emplace_back(revision, static_cast<std::uint64_t>(first_changed));
}

std::size_t ChangeLog::LaneChangedFrom(std::uint64_t id, std::uint64_t since) const {
  const auto it = lane_changes_.find(id);
  if (it == lane_changes_.end()) return 0;
  const auto first = After(it->second, since);
  return first == it->second.end() ? 0 : static_cast<std::size_t>(first->second);
}

void ChangeLog::NoteRemoved(ElementKind kind, std::uint64_t id) {
  if (kind == ElementKind::kLane) lane_changes_.erase(id);
  std::vector<Entry>& log = kind == ElementKind::kMarking ? removed_markings_ : removed_lanes_;
  log.emplace_back(Next(), id);
}

void ChangeLog::NoteRetiredMoved(std::size_t index) {
  retired_moved_.emplace_back(Next(), static_cast<std::uint64_t>(index));
}

std::vector<ChangeLog::Entry>::const_iterator ChangeLog::After(const std::vector<Entry>& log,
                                                               std::uint64_t since) {
  return std::upper_bound(log.begin(), log.end(), since,
                          [](std::uint64_t r, const Entry& e) { return r < e.first; });
}

std::vector<std::pair<std::uint64_t, std::uint64_t>> ChangeLog::RetiredSince(
    std::uint64_t since) const {
  return std::vector<Entry>(After(retired_, since), retired_.end());
}

std::vector<std::uint64_t> ChangeLog::RemovedSince(ElementKind kind, std::uint64_t since) const {
  const std::vector<Entry>& log =
      kind == ElementKind::kMarking ? removed_markings_ : removed_lanes_;
  std::vector<std::uint64_t> ids;
  for (auto it = After(log, since); it != log.end(); ++it) ids.push_back(it->second);
  return ids;
}

std::vector<std::size_t> ChangeLog::RetiredMovedSince(std::uint64_t since) const {
  std::vector<std::size_t> slots;
  for (auto it = After(retired_moved_, since); it != retired_moved_.end(); ++it) {
    slots.push_back(static_cast<std::size_t>(it->second));
  }
  return slots;
}

void ChangeLog::Clear() {
  cleared_at_ = Next();
  retired_.clear();
  removed_markings_.clear();
  removed_lanes_.clear();
  retired_moved_.clear();
  lane_changes_.clear();
}

std::size_t FirstChangedControlPoint(const std::vector<Eigen::Vector3d>& before,
                                     const std::vector<Eigen::Vector3d>& after) {
  const std::size_t n = std::min(before.size(), after.size());
  std::size_t i = 0;
  while (i < n && before[i] == after[i]) ++i;
  return i;
}

}  // namespace ipm_road_mapper
