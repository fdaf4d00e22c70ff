// The map's revisions: a counter the MapStore bumps on every change of an element's exported
// form (MapStore::Touch), and the logs an incremental export needs so that it never scans
// the retired markings: which retired markings changed at which revision, which element ids
// left the map at which revision, which retired slots another marking moved into (what
// a shared snapshot's chunks follow), and for each lane from which control point on it
// changed (so that a lane kilometers long that changed at its end costs its end only). The
// logs are appended in revision order.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <utility>
#include <vector>

#include "ipm_road_mapper/core/frontend/class_table.h"  // ElementKind

namespace ipm_road_mapper {

class ChangeLog {
 public:
  // A new revision, larger than every one before.
  std::uint64_t Next() { return ++revision_; }
  // The newest revision handed out (0: none).
  std::uint64_t revision() const { return revision_; }

  // Retired marking `id` changed (or retired) at `revision`.
  void NoteRetired(std::uint64_t revision, std::uint64_t id);
  // Element `id` of `kind` left the map; gets a new revision.
  void NoteRemoved(ElementKind kind, std::uint64_t id);
  // Lane `id` changed at `revision` from control point `first_changed` on (an index into
  // its control points then; 0: the whole lane, e.g. points prepended or a re-fit).
  void NoteLane(std::uint64_t revision, std::uint64_t id, std::size_t first_changed);
  // The first control point of lane `id` that changed after `since` (the least index noted
  // since then; 0 when nothing was noted: the whole lane). Points before it are as they
  // were at `since`, as long as every writer that moved points reported a range no larger
  // than the points it left in place (indices shift only with a 0).
  std::size_t LaneChangedFrom(std::uint64_t id, std::uint64_t since) const;
  // Retired marking slot `index` (an index into the retired markings) holds another marking
  // now (MapStore::ReviveMarking moved the last one there); gets a new revision.
  void NoteRetiredMoved(std::size_t index);

  // The (revision, id) entries of retired markings noted after `since`, oldest first; an
  // id may appear more than once (the caller keeps the entry matching its revision).
  std::vector<std::pair<std::uint64_t, std::uint64_t>> RetiredSince(std::uint64_t since) const;
  // The ids of `kind` removed after `since`, in removal order.
  std::vector<std::uint64_t> RemovedSince(ElementKind kind, std::uint64_t since) const;
  // The retired marking slots noted moved after `since`, oldest first.
  std::vector<std::size_t> RetiredMovedSince(std::uint64_t since) const;

  // Everything before now is forgotten (a reset): revisions keep counting, and a request
  // for changes since an older revision must take the whole map (cleared_at()).
  void Clear();
  // The revision of the last Clear (0: never).
  std::uint64_t cleared_at() const { return cleared_at_; }

 private:
  using Entry = std::pair<std::uint64_t, std::uint64_t>;  // (revision, id)
  static std::vector<Entry>::const_iterator After(const std::vector<Entry>& log,
                                                  std::uint64_t since);

  std::uint64_t revision_ = 0;
  std::uint64_t cleared_at_ = 0;
  std::vector<Entry> retired_;
  std::vector<Entry> removed_markings_, removed_lanes_;
  std::vector<Entry> retired_moved_;  // (revision, slot)
  // Per lane, (revision, first changed point) with strictly increasing points: an entry
  // whose point is no less than a newer one's never decides a minimum, so it is dropped;
  // the least point after `since` is then the first entry after it. At most one entry per
  // control point; a lane's entries go when it leaves the map.
  std::unordered_map<std::uint64_t, std::vector<Entry>> lane_changes_;
};

// The first index at which `after` differs from `before` (their common length when one is
// the other's start; after.size() when equal): the range a writer reports that replaced a
// lane's control points whole (a merge, a join).
std::size_t FirstChangedControlPoint(const std::vector<Eigen::Vector3d>& before,
                                     const std::vector<Eigen::Vector3d>& after);

}  // namespace ipm_road_mapper
