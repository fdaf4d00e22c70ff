// The lane half of the front end: point selection (PS) on each lane observation,
// association with the mapped lanes, starting a lane with g, growing its ends (FitLaneEnds),
// merging lanes that turn out to be one line, dropping lanes seen once, and the re-fit of
// lanes that no lane residual refines (export).
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <limits>
#include <optional>
#include <vector>

#include "ipm_road_mapper/core/frontend/observations.h"
#include "ipm_road_mapper/core/geometry/pinhole_camera.h"
#include "ipm_road_mapper/core/mapper/lane_gap_visibility.h"
#include "ipm_road_mapper/core/mapper/lane_path_bridge.h"
#include "ipm_road_mapper/core/mapper/map_store.h"
#include "ipm_road_mapper/core/mapper/mapper_counters.h"
#include "ipm_road_mapper/core/mapper/mapper_options.h"

namespace ipm_road_mapper {

class LaneTracker {
 public:
  // `options.association` must be the effective gates (EffectiveAssociationOptions). The
  // store and counters outlive the tracker.
  LaneTracker(const MapperOptions& options, MapStore* store, MapperCounters* counters);

  // One frame's lane observations in the map frame and the lanes they continue, before any
  // lane changes (Associate); what Update applies.
  struct FrameAssociation {
    std::vector<LaneCandidate> candidates;
    std::vector<LaneMeasurement> measurements;
    std::vector<std::size_t> near;  // the lanes within the candidates' reach
    std::vector<int> match;         // per candidate: its lane's index, or -1
  };

  // One frame: associates its lane observations, starts or grows lanes; every
  // lanes.merge_every_n_frames frames, merges lanes that are one line.
  void Update(const std::vector<LaneObservation>& observations, const FrameRecord& frame);
  // The same in two steps, so that the association is also read before the lanes change
  // (OffsetAcross): Update(Associate(o, f), f) is Update(o, f), as long as no lane changes
  // between the two calls.
  FrameAssociation Associate(const std::vector<LaneObservation>& observations,
                             const FrameRecord& frame) const;
  void Update(FrameAssociation association, const FrameRecord& frame);
  // The camera and extrinsic the frames are seen with, for the joins across a gap no frame
  // saw at the end of the drive (lane_gap_visibility.h); until it is set no such gap is
  // joined.
  void SetCamera(const CameraIntrinsics& camera, const Eigen::Isometry3d& T_base_cam);
  // The offset (m) across the frame's heading that puts its lane observations on the lanes
  // they continue (median over the lanes of LaneOffsetAcross), if any continues one: the
  // frame's pose error across the road, as the map's lanes see it. For the markings'
  // association (frame_registration.h).
  std::optional<double> OffsetAcross(const FrameAssociation& association,
                                     const FrameRecord& frame) const;
  // Drops the lanes seen in one frame only and not again for
  // association.spurious_after_frames frames.
  void DropSpurious(std::size_t frame_index);
  // Joins the lanes that continue one another (LaneContinues), until none does; runs with
  // the merge and at the end of the drive, where it also joins across a gap no frame saw
  // (JoinCost). Online only junctions whose data (the first's last and the second's first
  // observation) is older than `settled_before_frame`: a join
  // inside the windows ties the data on both sides of a gap with the bridge's smoothness
  // while the windows still solve the poses and extrinsic around it, which moved the
  // extrinsic's lateral lever arm by 2 cm on public_road (docs/backend.md).
  void JoinFragments(std::size_t settled_before_frame = std::numeric_limits<std::size_t>::max());
  // The frame before which lane data is settled: LaneContextStart when a lane residual
  // refines lanes in the windows, else the frame count (no window uses lane data).
  std::size_t SettledBefore() const;

  // The lane's control points re-fit to all its selected pixels, IPMed with `T_base_cam`
  // and the frames' current poses (export of lanes no lane residual refines).
  std::vector<Eigen::Vector3d> RefitControlPoints(const LaneElement& lane,
                                                  const CameraIntrinsics& camera,
                                                  const Eigen::Isometry3d& T_base_cam) const;

 private:
  // Starts a lane unless the observation is short, near a lane (loose gates) or along a
  // mapped lane of another class.
  void Start(int class_id, const LaneMeasurement& measurement,
             const std::vector<Eigen::Vector3d>& usable_map, const FrameRecord& frame);
  // Grows the lane's ends with this frame's usable points and refines them with the
  // selected points of its recent observations; returns the first control point it changed.
  std::size_t Grow(LaneElement* lane, std::size_t frame_index,
                   const std::vector<Eigen::Vector3d>& usable_map) const;
  void MergeLines();
  // The join cost of the pair (LaneJoinCost), or -1; `at_end` (the end of the drive) also
  // when it passes only as a gap no frame saw, bridged along the driven path
  // (lanes.join_max_hidden_gap_m, lane_path_bridge.h): the offsets' disagreement in combined
  // floor sigmas, with that bridge in `*hidden_bridge` (else it is reset). Such a bridge is
  // measured by no pixel: joined online, the windows that later solve the rest of the lane moved
  // curvy's extrinsic rotation 0.090 -> 0.099 deg (docs/backend.md), so it is laid only when no
  // window follows.
  double JoinCost(const LaneElement& first, const LaneElement& second, bool at_end,
                  std::optional<PathBridge>* hidden_bridge) const;
  // The frames around the gap between the first's end and the second's start (GapFrameSpan),
  // and the path bridge over it (BridgeAlongPath), or nullopt.
  FrameSpan GapSpan(const LaneElement& first, const LaneElement& second) const;
  std::optional<PathBridge> HiddenGapBridge(const LaneElement& first, const LaneElement& second,
                                            const FrameSpan& span) const;
  // The margin about an observation's points within which a lane can explain it.
  double AssociationMarginM() const;
  // The lanes (ascending indices into the store's lanes) that can have changed since the
  // last merge, and the lanes within a merge's or join's reach of them: those near the
  // vehicle. A superset; a merge or join of two other lanes was decided before.
  std::vector<std::size_t> LanesThatMayHaveChanged() const;

  const MapperOptions& options_;
  MapStore* store_;
  MapperCounters* counters_;
  // The frame's lanes near its observations (Update), and the lanes it started.
  std::vector<std::size_t> near_;
  GapCamera gap_camera_;
};

}  // namespace ipm_road_mapper
