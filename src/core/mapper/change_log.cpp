#include "ipm_road_mapper/core/mapper/change_log.h"

#include <algorithm>

namespace ipm_road_mapper {

void ChangeLog::NoteRetired(std::uint64_t revision, std::uint64_t id) {
  retired_.emplace_back(revision, id);
}

void ChangeLog::NoteRemoved(ElementKind kind, std::uint64_t id) {
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
}

}  // namespace ipm_road_mapper
