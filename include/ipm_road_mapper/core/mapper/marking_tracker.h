// The marking half of the front end: each frame's marking observations re-oriented along
// the road, associated with the mapped markings, turned into new elements or added to their
// element's history (with the plain-IPM running mean of the corners until the back end owns
// an element), elements that turn out to be one marking merged, and elements seen once and
// never again dropped as spurious.
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <vector>

#include "ipm_road_mapper/core/frontend/observations.h"
#include "ipm_road_mapper/core/geometry/ipm.h"
#include "ipm_road_mapper/core/mapper/map_store.h"
#include "ipm_road_mapper/core/mapper/mapper_counters.h"
#include "ipm_road_mapper/core/mapper/mapper_options.h"

namespace ipm_road_mapper {

class MarkingTracker {
 public:
  // `options.association` must be the effective gates (EffectiveAssociationOptions). The
  // store and counters outlive the tracker.
  MarkingTracker(const MapperOptions& options, MapStore* store, MapperCounters* counters);

  // One frame: orients, associates, creates or extends elements, merges duplicates.
  // Observations whose re-oriented rectangle leaves the image are dropped (and counted).
  // `offset_across_m`: the frame's pose error across its heading as the lanes measure it
  // (LaneTracker::OffsetAcross), for association in the registered frame
  // (frame_registration.h).
  // `road_ahead_map`: the road ahead from the trajectory, for the far-only markings no pose
  // has passed yet (FarOnlyEstimate); none: the newest pose's plane.
  void Update(const Ipm& ipm, const FrameRecord& frame,
              std::vector<MarkingObservation>* observations,
              std::optional<double> offset_across_m = std::nullopt,
              const RoadPlane* road_ahead_map = nullptr);
  // Drops the elements seen in one frame only and not again for
  // association.spurious_after_frames frames, and the tentative ones that frames where they
  // should have been visible did not see (CheckConsistency).
  void DropSpurious(std::size_t frame_index);
  // Re-estimates the far-only elements (FarOnlyEstimate) with the camera, T_base_cam and the
  // poses as they are now: the live ones, and the retired ones too when include_retired
  // (the end of the drive, after the final solve moved the poses).
  void RefreshFarOnly(const PinholeCamera& camera, const Eigen::Isometry3d& T_base_cam,
                      bool include_retired, const RoadPlane* road_ahead_map = nullptr);
  // The end of the drive, after the final solve: the unmeasured sides of every element seen
  // only in partial views (live and retired), measured again on the road plane from the
  // corrected poses (PartialExtentOnRoad).
  void RemeasurePartialExtents(const PinholeCamera& camera, const Eigen::Isometry3d& T_base_cam);

 private:
  // New corners of an element, or none to keep its own.
  using CornerEstimate =
      std::function<std::optional<std::array<Eigen::Vector3d, 4>>(const MarkingElement&)>;
  // Replaces each live element's corners (and each retired one's when include_retired) by
  // `estimate`'s where they moved by 1 mm or more: touched for the export, the retired index
  // rebuilt when one of those moved.
  void ReestimateCorners(const CornerEstimate& estimate, bool include_retired);
  // Re-fits each observation's rectangle with sides along the road (the tangent of the
  // nearest mapped lane): the ground truth's rectangles follow the road, and the vehicle's
  // heading is 5 deg off it on a 150 m curve 15 m ahead.
  void OrientAlongRoad(const Ipm& ipm, const FrameRecord& frame,
                       std::vector<MarkingObservation>* observations);
  void Associate(const std::vector<MarkingObservation>& observations, const FrameRecord& frame,
                 std::optional<double> offset_across_m);
  // Counts, for each tentative live element, whether this frame should have seen it and
  // whether it did; confirms the consistent ones.
  void CheckConsistency(const Ipm& ipm, const FrameRecord& frame);
  // Merges elements of one class closer than association.marking_merge_distance_m, whose
  // rectangles overlap by association.marking_merge_overlap, or, when no frame saw both and
  // each is the other's nearest such element, within the gate of their combined uncertainty
  // or with pixels that agree (PixelsAgree: one's views saw the other).
  void MergeDuplicates(const Ipm& ipm);

  const MapperOptions& options_;
  MapStore* store_;
  MapperCounters* counters_;
};

}  // namespace ipm_road_mapper
