// Joining the fragments of one line (lane_join.h): fragments of a dashed line across a gap
// and of an arc of R 30 m join into one lane on the line; the halves of a double line
// (0.2-0.5 m apart, seen in the same frames), a line that ends before another lane's line
// starts beside it or far ahead, and lines of different classes stay apart. An outer line
// whose points stray with the body's pitch (+-0.5 m, correlated over frames) still joins.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>

#include "common/lane_fragments.h"
#include "ipm_road_mapper/core/geometry/catmull_rom_spline.h"
#include "ipm_road_mapper/core/mapper/lane_join.h"

namespace ipm_road_mapper {
namespace {

using test::Arc;
using test::Line;
using test::MakeLane;
using test::Straight;

// Largest distance of the lane's curve, sampled every 0.5 m, from `line` over [s0, s1].
double MaxDistanceFrom(const LaneElement& lane, const Line& line, double s0, double s1) {
  const CatmullRomSpline spline(lane.control_points_map);
  std::vector<Eigen::Vector3d> dense;
  for (double s = s0 - 5.0; s <= s1 + 5.0; s += 0.05) dense.push_back(line(s));
  double worst = 0.0;
  for (const Eigen::Vector3d& p : spline.SampleByArcLength(0.5)) {
    double best = 1e9;
    for (const Eigen::Vector3d& q : dense) best = std::min(best, (p - q).norm());
    worst = std::max(worst, best);
  }
  return worst;
}

// `lane` as an outer line seen through a pitching body: every frame's points moved across
// the line by amplitude_m sin(2 pi f / period) (one stray for consecutive frames), each
// point with the lateral IPM sigma lateral_sigma_m (Omega_p in base_link; the vehicle heads
// +x, 8 m behind the frame's nearest point).
LaneElement WithPitchStray(LaneElement lane, double amplitude_m, double period_frames,
                           double lateral_sigma_m) {
  for (LaneMeasurement& m : lane.history) {
    const double stray = amplitude_m * std::sin(2.0 * M_PI * m.frame_index / period_frames);
    const Eigen::Vector3d vehicle(m.selected_map.front().x() - 8.0, 0.0, 0.0);
    m.points.clear();
    m.selected.assign(m.selected_map.size(), 1);
    for (Eigen::Vector3d& p : m.selected_map) {
      p.y() += stray;
      LanePoint point;
      point.p_base = p - vehicle;
      point.cov_base = Eigen::Vector2d(0.5, lateral_sigma_m * lateral_sigma_m).asDiagonal();
      point.score = point.cov_base.trace();
      m.points.push_back(point);
    }
  }
  return lane;
}

TEST(LaneJoin, FragmentsOfAnOuterLineStrayingWithThePitchJoin) {
  // The 10 km drive's solid line 5.25 m aside: the ends of its two fragments stray with the
  // last frames' pitch, by more than the floor sigma can explain (docs/backend.md). With
  // the floor sigma alone (the models before) they stay apart.
  std::mt19937 rng(6);
  const Line line = Straight(-5.25);
  const double amplitude_m = 0.5, period_frames = 18.0, sigma_m = 0.12;
  const LaneElement a = WithPitchStray(MakeLane(1, 1, line, 0.0, 40.0, 0, 40, &rng), amplitude_m,
                                       period_frames, sigma_m);
  const LaneElement b = WithPitchStray(MakeLane(2, 1, line, 46.0, 100.0, 45, 100, &rng),
                                       amplitude_m, period_frames, sigma_m);
  LaneJoinOptions floor_only;
  floor_only.ipm_correlation_frames = 0.0;
  EXPECT_TRUE(LaneContinues(a, b, LaneJoinOptions(), AssociationOptions()));
  EXPECT_FALSE(LaneContinues(a, b, floor_only, AssociationOptions()));
  // The next lane's line (3.5 m beside), seen through the same pitch, still stays apart.
  for (const double y : {-1.75, -8.75}) {
    const LaneElement beside =
        WithPitchStray(MakeLane(3, 1, Straight(y), 46.0, 100.0, 45, 100, &rng), amplitude_m,
                       period_frames, sigma_m);
    EXPECT_FALSE(LaneContinues(a, beside, LaneJoinOptions(), AssociationOptions())) << y;
  }
  // Nor when it is seen in only a few frames (noisier still): fewer observations than the
  // correlation length together know their line no worse than one of them (uncapped, the
  // line 3.5 m beside passed at cost 2.7).
  for (const double y : {-1.75, -8.75}) {
    const LaneElement short_beside = WithPitchStray(
        MakeLane(4, 1, Straight(y), 46.0, 55.0, 45, 49, &rng), amplitude_m, period_frames, 0.2);
    EXPECT_FALSE(LaneContinues(a, short_beside, LaneJoinOptions(), AssociationOptions())) << y;
  }
}

TEST(LaneJoin, FragmentsOfOneDashedLineAcrossAGapJoin) {
  std::mt19937 rng(1);
  const Line line = Straight(1.75);
  const LaneElement a = MakeLane(1, 2, line, 0.0, 40.0, 0, 40, &rng);
  const LaneElement b = MakeLane(7, 2, line, 46.0, 100.0, 60, 120, &rng);
  const LaneJoinOptions join;
  const AssociationOptions options;
  ASSERT_TRUE(LaneContinues(a, b, join, options));
  EXPECT_FALSE(LaneContinues(b, a, join, options));  // b does not lead into a
  const auto joined = JoinLanes(a, b, join, options, 3.0);
  ASSERT_TRUE(joined.has_value());
  EXPECT_EQ(joined->id, 1u);
  EXPECT_EQ(joined->first_cp_index, a.first_cp_index);
  EXPECT_EQ(joined->history.size(), a.history.size() + b.history.size());
  EXPECT_EQ(joined->last_frame, 119u);
  const CatmullRomSpline spline(joined->control_points_map);
  EXPECT_NEAR(spline.Length(), 100.0, 3.0);
  EXPECT_LT(MaxDistanceFrom(*joined, line, 0.0, 100.0), 0.1);
}

TEST(LaneJoin, FragmentsOfAnArcOfRadius30mJoin) {
  std::mt19937 rng(2);
  const Line line = Arc(30.0, 1.75);
  const LaneElement a = MakeLane(1, 2, line, 0.0, 20.0, 0, 30, &rng);
  const LaneElement b = MakeLane(2, 2, line, 26.0, 45.0, 40, 70, &rng);
  ASSERT_TRUE(LaneContinues(a, b, LaneJoinOptions(), AssociationOptions()));
  const auto joined = JoinLanes(a, b, LaneJoinOptions(), AssociationOptions(), 3.0);
  ASSERT_TRUE(joined.has_value());
  EXPECT_LT(MaxDistanceFrom(*joined, line, 0.0, 45.0), 0.15);
}

TEST(LaneJoin, HalvesOfADoubleLineStayApart) {
  for (const double spacing : {0.2, 0.35, 0.5}) {
    std::mt19937 rng(3);
    // Seen together (two instances of every frame), the right half starting a little later.
    const LaneElement left = MakeLane(1, 2, Straight(0.0), 0.0, 40.0, 0, 40, &rng);
    const LaneElement right = MakeLane(2, 2, Straight(-spacing), 10.0, 60.0, 10, 60, &rng);
    EXPECT_TRUE(CoObserved(left, right));
    EXPECT_FALSE(LaneContinues(left, right, LaneJoinOptions(), AssociationOptions())) << spacing;
  }
}

TEST(LaneJoin, ALineWhoseInstanceAnOccluderSplitIsJoined) {
  std::mt19937 rng(5);
  // One line; over frames 30-39 a vehicle on it splits its instance in two: the near piece
  // continues lane a, the far one, 4 m on past the vehicle, starts lane b.
  const LaneElement a = MakeLane(1, 2, Straight(0.0), 0.0, 40.0, 0, 40, &rng);
  LaneElement b = MakeLane(2, 2, Straight(0.0), 44.0, 80.0, 40, 80, &rng);
  std::vector<LaneMeasurement> split;
  for (const LaneMeasurement& m : a.history) {
    if (m.frame_index < 30) continue;
    LaneMeasurement far = m;
    for (Eigen::Vector3d& p : far.selected_map) p.x() += 7.0;  // beyond the vehicle
    split.push_back(far);
  }
  b.history.insert(b.history.begin(), split.begin(), split.end());
  b.first_frame = 30;
  // Seen in one frame, but end to end: one line.
  EXPECT_FALSE(CoObserved(a, b));
  EXPECT_TRUE(LaneContinues(a, b, LaneJoinOptions(), AssociationOptions()));
  // The same two instances side by side (a double line's halves 0.3 m apart) stay apart.
  LaneElement beside = b;
  for (std::size_t k = 0; k < split.size(); ++k) {
    for (Eigen::Vector3d& p : beside.history[k].selected_map) p += Eigen::Vector3d(-7.0, -0.3, 0.0);
  }
  EXPECT_TRUE(CoObserved(a, beside));
  EXPECT_FALSE(LaneContinues(a, beside, LaneJoinOptions(), AssociationOptions()));
  // End to end but on the next lane's line, 3.5 m across (short pieces: av2_pit_dev's
  // solid lines, where the union of the two pieces' points is widest across): two lines.
  LaneElement staggered = b;
  for (std::size_t k = 0; k < split.size(); ++k) {
    for (Eigen::Vector3d& p : staggered.history[k].selected_map) p.y() += 3.5;
  }
  EXPECT_TRUE(CoObserved(a, staggered));
}

TEST(LaneJoin, ALineThatEndsIsNotContinuedByAnotherLine) {
  std::mt19937 rng(4);
  const LaneElement ends = MakeLane(1, 2, Straight(0.0), 0.0, 40.0, 0, 40, &rng);
  // The next lane's line beside it (either side), a line 1 m beside it (a lane shift), and
  // the same line far ahead (30 m, beyond join_max_gap_m).
  for (const double y : {3.5, -3.5, 1.0}) {
    const LaneElement beside = MakeLane(2, 2, Straight(y), 46.0, 90.0, 60, 110, &rng);
    EXPECT_FALSE(LaneContinues(ends, beside, LaneJoinOptions(), AssociationOptions())) << y;
  }
  const LaneElement far = MakeLane(3, 2, Straight(0.0), 70.0, 110.0, 80, 120, &rng);
  EXPECT_FALSE(LaneContinues(ends, far, LaneJoinOptions(), AssociationOptions()));
  // A line leaving at 20 deg (a fork's branch) does not continue it either.
  const double c = std::cos(20.0 * M_PI / 180.0), s = std::sin(20.0 * M_PI / 180.0);
  const Line branch = [c, s](double t) { return Eigen::Vector3d(42.0 + c * t, s * t, 0.0); };
  const LaneElement fork = MakeLane(4, 2, branch, 0.0, 40.0, 60, 100, &rng);
  EXPECT_FALSE(LaneContinues(ends, fork, LaneJoinOptions(), AssociationOptions()));
}

TEST(LaneJoin, LinesOfDifferentClassesStayApart) {
  std::mt19937 rng(5);
  const LaneElement dashed = MakeLane(1, 2, Straight(0.0), 0.0, 40.0, 0, 40, &rng);
  const LaneElement solid = MakeLane(2, 1, Straight(0.0), 46.0, 90.0, 60, 110, &rng);
  EXPECT_FALSE(LaneContinues(dashed, solid, LaneJoinOptions(), AssociationOptions()));
}

}  // namespace
}  // namespace ipm_road_mapper
