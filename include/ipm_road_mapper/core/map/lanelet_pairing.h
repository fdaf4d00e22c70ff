// Lanelets from the mapped lane lines: which two lines bound one lane, and where.
//
// A Lanelet2 lanelet has one left and one right bound, both line strings running in the
// direction of travel, and neighbouring lanelets share the line between them. The map has
// lane lines only, so the lanes are found here:
// - every line is a polyline oriented along the drive (LaneOrientedAlongDrive);
// - at each sample of a line, its left neighbour is the nearest other line to its left whose
//   nearest segment is parallel (within kMaxNeighbourAngleRad) and lies kMinLaneWidthM to
//   kMaxLaneWidthM away; when the nearest line to its left is closer than that (the two
//   lines of a double line) it has no left neighbour there: the double is one boundary and
//   the lane beyond it starts at its other line;
// - a run of consecutive samples with the same left neighbour, at least kMinLaneletLengthM
//   long, is one lane: right bound this line over the run, left bound the neighbour over the
//   run's projection on it;
// - a bound may take part in several lanes (a line is the left bound of the lane to its
//   right and the right bound of the lane to its left), and each lanelet needs exactly one
//   piece of each line: every line is cut where one of its runs starts or ends, and a cut
//   inside a run is carried across the lane to the other bound (and on, until nothing
//   changes), so the pieces of the two bounds of a lane correspond one to one. A chain of
//   lanelets along a lane then shares its cut points, which is how Lanelet2 tells that one
//   follows the other.
// A run whose pieces still do not correspond is left out and counted. No ROS header.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "ipm_road_mapper/core/geometry/rigid_transform.h"

namespace ipm_road_mapper {

constexpr double kMinLaneWidthM = 2.2;
constexpr double kMaxLaneWidthM = 5.0;
constexpr double kMaxNeighbourAngleRad = 20.0 * 3.14159265358979323846 / 180.0;
constexpr double kMinLaneletLengthM = 10.0;
// Cuts closer than this along a line are one cut, and a line is not cut closer than
// kEndSnapM to its ends (a line first seen a few metres later than its neighbour starts its
// lane with it): no lanelet is a sliver.
constexpr double kMergeCutsM = 2.0;
constexpr double kEndSnapM = kMinLaneletLengthM;

// One lanelet: the piece `right_piece` of line `right_line` and the piece `left_piece` of
// line `left_line` (pieces numbered along the line, between its cuts).
struct LaneletBounds {
  std::size_t right_line = 0, right_piece = 0;
  std::size_t left_line = 0, left_piece = 0;
};

struct LaneletLayout {
  // Per line, the arc lengths (m, along the oriented polyline) where it is cut, ascending,
  // without its ends: line i has cuts[i].size() + 1 pieces.
  std::vector<std::vector<double>> cuts;
  std::vector<LaneletBounds> lanelets;
  std::size_t runs_left_out = 0;  // lanes found whose bounds' pieces did not correspond
};

// The polyline reversed when the drive went the other way along it: its direction at the
// sample nearest to the trajectory's poses (the nearest pose to its middle sample) against
// that pose's heading. Unchanged without a trajectory. With `reversed`, whether it was.
std::vector<Eigen::Vector3d> LaneOrientedAlongDrive(std::vector<Eigen::Vector3d> polyline,
                                                    const std::vector<StampedPose>& trajectory,
                                                    bool* reversed = nullptr);

// The lanelets between `lines` (oriented polylines, map frame; see the file comment).
LaneletLayout PairLanelets(const std::vector<std::vector<Eigen::Vector3d>>& lines);

// Segments longer than this are not indexed: no lane line has one, and a hostile map's
// kilometre-long segment would fill the grid.
constexpr double kMaxIndexedSegmentM = 1000.0;

// The arc-length range [from, to] of piece `piece` of line `line` (between its cuts, or the
// line's ends: `length_m`).
std::pair<double, double> PieceRange(const LaneletLayout& layout, std::size_t line,
                                     std::size_t piece, double length_m);

// Arc length of each sample of a polyline (x-y), starting at 0.
std::vector<double> ArcLengths(const std::vector<Eigen::Vector3d>& polyline);

// The point at arc length s along the polyline (x-y arc length, linear in between; s clamped
// to the polyline's ends).
Eigen::Vector3d PointAtArcLength(const std::vector<Eigen::Vector3d>& polyline,
                                 const std::vector<double>& arc, double s);

}  // namespace ipm_road_mapper
