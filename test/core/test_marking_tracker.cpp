// The marking tracker alone, on observations extracted from rendered masks: a marking seen
// again is one element with the running mean of its corners, a duplicate element of one
// class at one place is merged (and one of another class is not), and an element seen once
// is dropped after the spurious horizon.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <vector>

#include "common/road_scene.h"
#include "ipm_road_mapper/core/frontend/instance_extraction.h"
#include "ipm_road_mapper/core/mapper/marking_tracker.h"

namespace ipm_road_mapper {
namespace {

using namespace test;  // NOLINT: the scene's helpers

struct Rig : RoomRig {
  explicit Rig(MapperOptions o = MapperOptions()) : RoomRig(std::move(o)) {}
  // Extracts the frame's observations and runs the tracker on them.
  void Step(const FrameInput& in) {
    std::optional<Ipm> ipm;
    FrameObservations obs = Observe(in, TestExtrinsic(), &ipm);
    const FrameRecord& frame = store.AddFrame(in.stamp, in.T_map_base_odom);
    tracker.Update(*ipm, frame, &obs.markings);
    tracker.DropSpurious(frame.index);
  }
  MarkingTracker tracker{options, &store, &counters};
};

TEST(MarkingTracker, ReobservedMarkingIsOneElementWithTheMeanOfItsCorners) {
  Rig rig;
  for (int k = 0; k < 6; ++k) rig.Step(RoadFrame(100.0 + 0.05 * k, 0.5 * k));
  ASSERT_EQ(rig.store.markings().size(), 1u);
  const MarkingElement& arrow = rig.store.markings()[0];
  EXPECT_EQ(arrow.history.size(), 6u);
  EXPECT_EQ(arrow.first_frame, 0u);
  EXPECT_EQ(arrow.last_frame, 5u);
  EXPECT_NEAR(arrow.Center().x(), 21.5, 0.15);
  EXPECT_NEAR(arrow.Center().y(), 0.0, 0.05);
  EXPECT_EQ(rig.counters.markings_created, 1u);
  EXPECT_FALSE(arrow.optimized);
}

TEST(MarkingTracker, DuplicatesOfOneClassMergeOthersDoNot) {
  Rig rig;
  rig.Step(RoadFrame(100.0, 0.0));
  ASSERT_EQ(rig.store.markings().size(), 1u);
  // A second element of the arrow's class 0.3 m beside it (a missed association), and one
  // of another class at the same place.
  MarkingElement copy = rig.store.markings()[0];
  copy.id = rig.store.NewId();
  for (Eigen::Vector3d& c : copy.corners_map) c.y() += 0.3;
  copy.history[0].frame_index = 0;
  MarkingElement other = copy;
  other.id = rig.store.NewId();
  other.class_id = 11;
  rig.store.markings().push_back(copy);
  rig.store.markings().push_back(other);
  rig.Step(RoadFrame(100.05, 0.5));
  ASSERT_EQ(rig.store.markings().size(), 2u);
  EXPECT_EQ(rig.counters.markings_merged, 1u);
  const MarkingElement& arrow = rig.store.markings()[0];
  EXPECT_EQ(arrow.class_id, 10);
  // One measurement per frame: frame 0's twice-held measurement kept once, plus frame 1's.
  EXPECT_EQ(arrow.history.size(), 2u);
}

// An element like `like` but of class 11, a 3 m x 0.5 m rectangle (long along the road)
// centered at (x, y), seen in frame `frame` only.
MarkingElement Stripe(Rig* rig, const MarkingElement& like, double x, double y, std::size_t frame) {
  MarkingElement e = like;
  e.id = rig->store.NewId();
  e.class_id = 11;
  e.corners_map = {Eigen::Vector3d(x - 1.5, y - 0.25, 0.0), Eigen::Vector3d(x + 1.5, y - 0.25, 0.0),
                   Eigen::Vector3d(x + 1.5, y + 0.25, 0.0),
                   Eigen::Vector3d(x - 1.5, y + 0.25, 0.0)};
  e.history.resize(1);
  e.history[0].frame_index = frame;
  return e;
}

// The mapper told 0.5 m odometry (pose prior 0.75 m, as the benchmark tells it): the
// uncertainty gate of a merge then spans meters.
MapperOptions NoisyOdometryOptions() {
  MapperOptions o;
  o.backend.pose_prior_sigma_trans_m = Eigen::Vector3d(0.75, 0.75, 0.02);
  return o;
}

TEST(MarkingTracker, LoneCopyWithinTheUncertaintyGateMerges) {
  // A marking's second element, never seen in one frame with the first, 1.2 m beside it
  // (neither near nor overlapping): the uncertainty gate merges them.
  Rig rig(NoisyOdometryOptions());
  rig.Step(RoadFrame(100.0, 0.0));
  rig.Step(RoadFrame(100.05, 0.5));
  ASSERT_EQ(rig.store.markings().size(), 1u);
  const MarkingElement arrow = rig.store.markings()[0];
  rig.store.markings().push_back(Stripe(&rig, arrow, 30.0, 5.0, 0));
  rig.store.markings().push_back(Stripe(&rig, arrow, 30.0, 6.2, 1));
  rig.Step(RoadFrame(100.10, 1.0));
  EXPECT_EQ(rig.counters.markings_merged, 1u);
  EXPECT_EQ(rig.store.markings().size(), 2u);
}

TEST(MarkingTracker, FarOnlyElementMeetsANearOneByPlaceNotByTheGate) {
  // As above, but the second element was made by far views: its gate is their Omega_p
  // (meters), wider than a crossing's stripe spacing, so the gate does not pair it with a
  // near-seen neighbour 1.2 m away (on urban it took a stripe's far-only element into the
  // next stripe's). Within the merge distance it merges, and the near-seen element stays.
  Rig rig(NoisyOdometryOptions());
  rig.Step(RoadFrame(100.0, 0.0));
  rig.Step(RoadFrame(100.05, 0.5));
  ASSERT_EQ(rig.store.markings().size(), 1u);
  const MarkingElement arrow = rig.store.markings()[0];
  rig.store.markings().push_back(Stripe(&rig, arrow, 30.0, 5.0, 0));
  const std::uint64_t near_id = rig.store.markings().back().id;
  MarkingElement far = Stripe(&rig, arrow, 30.0, 6.2, 1);
  far.far_only = true;
  // No views to re-estimate it from (the copied ones are the arrow's): it stays where it is.
  far.history.clear();
  far.pruned = 2;
  rig.store.markings().push_back(far);
  rig.Step(RoadFrame(100.10, 1.0));
  EXPECT_EQ(rig.counters.markings_merged, 0u);
  EXPECT_EQ(rig.store.markings().size(), 3u);
  // 0.3 m away: one marking; the near-seen element stays as it was.
  for (MarkingElement& m : rig.store.markings()) {
    if (!m.far_only) continue;
    for (Eigen::Vector3d& c : m.corners_map) c.y() -= 0.9;
  }
  rig.Step(RoadFrame(100.15, 1.5));
  EXPECT_EQ(rig.counters.markings_merged, 1u);
  ASSERT_EQ(rig.store.markings().size(), 2u);
  for (const MarkingElement& m : rig.store.markings()) {
    if (m.class_id != 11) continue;
    EXPECT_EQ(m.id, near_id);
    EXPECT_FALSE(m.far_only);
    EXPECT_EQ(m.history.size(), 1u);
  }
}

TEST(MarkingTracker, CopyAmongEvenlySpacedMarkingsMergesIntoTheNearest) {
  // Three stripes of a crossing 1 m apart, seen together, and an element of their class seen
  // in another frame 1.1 m from the middle one (1.8 m from the first): the gate (meters here)
  // holds all three, and the copy belongs to the nearest. It went to the first the store
  // listed: on public_road_noise_0.5 such merges moved the crossing's stripes from 1.0 to
  // 1.5 m off (marking APE 0.50 -> 0.75 m).
  Rig rig(NoisyOdometryOptions());
  rig.Step(RoadFrame(100.0, 0.0));
  rig.Step(RoadFrame(100.05, 0.5));
  ASSERT_EQ(rig.store.markings().size(), 1u);
  const MarkingElement arrow = rig.store.markings()[0];
  std::vector<std::uint64_t> stripe_ids;
  for (double y : {4.0, 5.0, 6.0}) {
    rig.store.markings().push_back(Stripe(&rig, arrow, 30.0, y, 0));
    stripe_ids.push_back(rig.store.markings().back().id);
  }
  rig.store.markings().push_back(Stripe(&rig, arrow, 31.0, 5.45, 1));
  rig.Step(RoadFrame(100.10, 1.0));
  EXPECT_EQ(rig.counters.markings_merged, 1u);
  ASSERT_EQ(rig.store.markings().size(), 4u);
  for (const MarkingElement& m : rig.store.markings()) {
    if (m.class_id != 11) continue;
    const bool middle = m.id == stripe_ids[1];
    EXPECT_EQ(m.history.size(), middle ? 2u : 1u) << "stripe " << m.id;
  }
}

TEST(MarkingTracker, RetiredMarkingSeenAgainIsTheSameElement) {
  Rig rig;
  for (int k = 0; k < 3; ++k) rig.Step(RoadFrame(100.0 + 0.05 * k, 0.5 * k));
  ASSERT_EQ(rig.store.markings().size(), 1u);
  const std::uint64_t id = rig.store.markings()[0].id;
  rig.store.markings()[0].retired = true;
  rig.store.RetireMarkings(100);  // left the window
  ASSERT_TRUE(rig.store.markings().empty());
  rig.Step(RoadFrame(100.15, 1.5));  // seen again after the gap
  ASSERT_EQ(rig.store.markings().size(), 1u);
  EXPECT_TRUE(rig.store.retired_markings().empty());
  EXPECT_EQ(rig.store.markings()[0].id, id);
  EXPECT_EQ(rig.store.markings()[0].history.size(), 4u);
  EXPECT_EQ(rig.counters.markings_created, 1u);
}

TEST(MarkingTracker, MarkingSeenOnceIsDroppedWhereItShouldHaveBeenSeenAgain) {
  // The arrow 20 m ahead is seen in one frame; the next frames look at the same place from
  // as near or nearer and do not see it: a spurious blob, dropped as inconsistent before
  // the seen-once horizon, and never confirmed.
  Rig rig;
  rig.Step(RoadFrame(100.0, 0.0));
  ASSERT_EQ(rig.store.markings().size(), 1u);
  EXPECT_FALSE(rig.store.markings()[0].confirmed);
  const int horizon = rig.options.association.spurious_after_frames;
  int dropped_after = -1;
  for (int k = 1; k <= horizon && dropped_after < 0; ++k) {
    rig.Step(RoadFrame(100.0 + 0.05 * k, 0.0, false));
    if (rig.store.markings().empty()) dropped_after = k;
  }
  EXPECT_GT(dropped_after, 0);
  EXPECT_LT(dropped_after, horizon);
  EXPECT_EQ(rig.counters.markings_inconsistent, 1u);
  EXPECT_EQ(rig.counters.spurious_dropped, 0u);
}

TEST(MarkingTracker, MarkingSeenEveryFrameIsConfirmed) {
  Rig rig;
  for (int k = 0; k < 4; ++k) rig.Step(RoadFrame(100.0 + 0.05 * k, 0.2 * k));
  ASSERT_EQ(rig.store.markings().size(), 1u);
  EXPECT_TRUE(rig.store.markings()[0].confirmed);
  EXPECT_EQ(rig.store.markings()[0].frames_seen, 3u);  // the count ends when confirmed
  EXPECT_EQ(rig.counters.markings_inconsistent, 0u);
}

// Far views beyond 10 m (the arrow at x in [20, 23] m is 20 m ahead of base_link at x = 0),
// kept as far views up to 40 m.
MapperOptions FarViewOptions() {
  MapperOptions o;
  o.extraction.max_marking_range_m = 10.0;
  o.extraction.far_marking_range_m = 40.0;
  return o;
}

TEST(MarkingTracker, FarViewsMapAMarkingNoNearViewShowsUntilANearViewRestartsIt) {
  Rig rig(FarViewOptions());
  for (int k = 0; k < 4; ++k) rig.Step(RoadFrame(100.0 + 0.05 * k, 0.5 * k));
  ASSERT_EQ(rig.store.markings().size(), 1u);
  const MarkingElement far = rig.store.markings()[0];
  EXPECT_TRUE(far.far_only);
  EXPECT_TRUE(far.confirmed);
  EXPECT_EQ(far.history.size(), 4u);
  EXPECT_NEAR(far.Center().x(), 21.5, 0.3);
  EXPECT_NEAR(far.Center().y(), 0.0, 0.1);
  // Seen near (9.5 m): the element starts again from the near view, under its id.
  rig.Step(RoadFrame(100.20, 12.0));
  ASSERT_EQ(rig.store.markings().size(), 1u);
  const MarkingElement& near = rig.store.markings()[0];
  EXPECT_EQ(near.id, far.id);
  EXPECT_FALSE(near.far_only);
  EXPECT_FALSE(near.confirmed);  // confirmed again by near views, as a new element would be
  EXPECT_EQ(near.history.size(), 1u);
  EXPECT_EQ(near.history[0].frame_index, 4u);
  EXPECT_EQ(rig.counters.markings_created, 1u);
  EXPECT_EQ(rig.counters.far_markings_restarted, 1u);
  EXPECT_EQ(rig.counters.far_markings_dropped, 0u);
}

TEST(MarkingTracker, FarOnlyMarkingNoNearViewFindsIsDropped) {
  // Confirmed by its far views, then not there when the vehicle is within 10 m of it and it
  // lies in the image: where the far views put it there is nothing, it goes.
  Rig rig(FarViewOptions());
  for (int k = 0; k < 4; ++k) rig.Step(RoadFrame(100.0 + 0.05 * k, 0.5 * k));
  ASSERT_EQ(rig.store.markings().size(), 1u);
  ASSERT_TRUE(rig.store.markings()[0].confirmed);
  int dropped_after = -1;
  for (int k = 0; k < 8 && dropped_after < 0; ++k) {
    rig.Step(RoadFrame(100.2 + 0.05 * k, 12.0 + 0.2 * k, /*with_arrow=*/false));
    if (rig.store.markings().empty()) dropped_after = k + 1;
  }
  EXPECT_EQ(dropped_after, 4);
  EXPECT_EQ(rig.counters.far_markings_dropped, 1u);
}

TEST(MarkingTracker, FarOnlyMarkingThatStopsBeingSeenWhereItShouldBeIsDropped) {
  // Confirmed by its far views, then no longer seen from 20 m (its center in the image, no
  // farther than its views were): it stays on probation, and goes once seen in fewer than
  // half the frames that should have seen it, before any near view could judge it.
  Rig rig(FarViewOptions());
  for (int k = 0; k < 4; ++k) rig.Step(RoadFrame(100.0 + 0.05 * k, 0.5 * k));
  ASSERT_EQ(rig.store.markings().size(), 1u);
  ASSERT_TRUE(rig.store.markings()[0].confirmed);
  int dropped_after = -1;
  for (int k = 0; k < 10 && dropped_after < 0; ++k) {
    rig.Step(RoadFrame(100.2 + 0.05 * k, 1.5 + 0.05 * k, /*with_arrow=*/false));
    if (rig.store.markings().empty()) dropped_after = k + 1;
  }
  EXPECT_GT(dropped_after, 0);
  EXPECT_EQ(rig.counters.far_markings_dropped, 1u);
  EXPECT_EQ(rig.store.markings().empty() ? 0u : rig.store.markings()[0].near_frames_expected, 0u);
}

TEST(MarkingTracker, FarViewIsNoMeasurementOfAMarkingSeenNear) {
  // Seen near three times, then from 20 m again (backing away): the far views associate
  // with it and are left out of its history.
  Rig rig(FarViewOptions());
  for (int k = 0; k < 3; ++k) rig.Step(RoadFrame(100.0 + 0.05 * k, 12.0 + 0.5 * k));
  ASSERT_EQ(rig.store.markings().size(), 1u);
  const std::array<Eigen::Vector3d, 4> corners = rig.store.markings()[0].corners_map;
  for (int k = 0; k < 3; ++k) rig.Step(RoadFrame(100.2 + 0.05 * k, 1.0 - 0.5 * k));
  ASSERT_EQ(rig.store.markings().size(), 1u);
  const MarkingElement& arrow = rig.store.markings()[0];
  EXPECT_FALSE(arrow.far_only);
  EXPECT_EQ(arrow.history.size(), 3u);
  for (int c = 0; c < 4; ++c) EXPECT_EQ(arrow.corners_map[c], corners[c]);
  EXPECT_EQ(rig.counters.markings_created, 1u);
}

}  // namespace
}  // namespace ipm_road_mapper
