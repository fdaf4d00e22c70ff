// What the front end extracts from one instance mask: per marking instance the 4 corners
// of its bounding rectangle (pixels and ground), per lane instance its centerline points
// (pixels, ground, IPM uncertainty score). Ground points are in base_link (z = 0).
#pragma once

#include <Eigen/Core>
#include <Eigen/LU>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace ipm_road_mapper {

// One marking instance of one frame.
struct MarkingObservation {
  int class_id = 0;
  int instance_value = 0;  // the mask pixel value, class_id * 1000 + instance_index
  // Corners of the marking's bounding rectangle on the ground, its sides along the road
  // (the rectangle of the ground truth): along base_link's x axis when extracted, along the
  // mapped lanes once the mapper re-orients it. Canonical order: starting at the corner
  // nearest base_link's origin, counter-clockwise seen from above.
  std::array<Eigen::Vector3d, 4> corners_base;
  // The same corners projected back into the image: the pixel measurements z_k.
  std::array<Eigen::Vector2d, 4> corners_uv;
  // The instance's convex outline in the image (sub-pixel) and on the ground (x-y in
  // base_link, its IPM), what the rectangle is fitted to. Where the IPM fails (beyond the
  // range, at the horizon) the outline is clipped: only the part that maps is kept.
  std::vector<Eigen::Vector2d> outline_uv;
  std::vector<Eigen::Vector2d> outline_base;
  // Per outline edge (vertex i to i + 1): 1 when it is no boundary of the marking but where
  // the view ends (the image border, an adjacent occluder or instance, the range clip).
  std::vector<std::uint8_t> outline_edge_cut;
  // Per side of the rectangle (side i runs from corners_base[i] to corners_base[i + 1]):
  // true when the marking's own boundary was seen there, false when the view cut it.
  std::array<bool, 4> side_measured{{true, true, true, true}};
  // Per measured side: pixels of the observed boundary on it (sampled outline points), the
  // measurements of the edge residual (edge_reprojection_residual.h). Empty for cut sides.
  std::array<std::vector<Eigen::Vector2d>, 4> side_uv;
  // A corner is a measurement only where both of its sides are.
  bool CornerMeasured(int i) const { return side_measured[(i + 3) % 4] && side_measured[i]; }
  // Every side measured: the whole marking was in view.
  bool Complete() const {
    return side_measured[0] && side_measured[1] && side_measured[2] && side_measured[3];
  }
  // Center of the rectangle (mean of corners_base) and the x-y block of Omega_p at its
  // pixel: how far plain IPM may have put it (m^2), for the association gate.
  Eigen::Vector3d center_base = Eigen::Vector3d::Zero();
  Eigen::Matrix2d center_cov_base = Eigen::Matrix2d::Zero();
  int pixel_count = 0;
  // Centered beyond ExtractionOptions::max_marking_range_m (a far view: whole, see there).
  bool far = false;
};

// One centerline point of a lane instance.
struct LanePoint {
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();        // pixel (the PPSR measurement)
  Eigen::Vector3d p_base = Eigen::Vector3d::Zero();    // its IPM ground point
  double score = 0.0;                                  // tr(Omega_p), m^2
  Eigen::Matrix2d cov_base = Eigen::Matrix2d::Zero();  // x-y block of Omega_p, m^2
};

// One lane instance of one frame (all dashes of one line share an instance).
struct LaneObservation {
  int class_id = 0;
  int instance_value = 0;
  std::vector<LanePoint> points;  // ordered by image row, bottom (near) first
  int pixel_count = 0;
};

// Slots of the per-class counters below: one per class id 0..65 (kMaxClassId, class_table.h).
constexpr int kClassIdSlots = 66;

// Why an instance (or a whole mask) was not used; counted, never silent.
struct ExtractionCounters {
  std::uint64_t instances_seen = 0;
  std::uint64_t dropped_unknown_class = 0;      // class id not in the class table
  std::uint64_t dropped_tiny = 0;               // fewer pixels than the class kind's minimum
  std::uint64_t dropped_border = 0;             // marking whose every side the view cuts
  std::uint64_t partial_markings = 0;           // markings kept with some side cut (not a drop)
  std::uint64_t dropped_range = 0;              // beyond max range or above the horizon
  std::uint64_t dropped_degenerate = 0;         // too few valid lane points / flat rectangle
  std::uint64_t dropped_instance_limit = 0;     // more instances than max_instances_per_frame
  std::uint64_t dropped_oversized = 0;          // marking larger than its class's max size
  std::uint64_t dropped_wide_lane = 0;          // lane whose runs are mostly wider than a line
  std::uint64_t dropped_absurd_frame = 0;       // candidates of frames dropped as absurd (below)
  std::uint64_t lane_runs_too_wide = 0;         // lane runs (points) wider than a line: no point
  std::uint64_t frames_too_many_instances = 0;  // frames over max_plausible_instances
  std::uint64_t frames_too_much_coverage = 0;   // frames over max_coverage
  // Lane rows (sampled) that cross their instance more than once; and lane instances with
  // more than a quarter of such rows (one that doubles back): dropped.
  std::uint64_t lane_rows_doubled = 0;
  std::uint64_t dropped_doubled_lane = 0;
  // Per marking class id: the views whose size was judged against the class's bounds (kept,
  // truncated or oversized), and those of them larger than the bounds. A class table that is
  // not the masks' own shows here (class_size_check.h).
  std::array<std::uint64_t, kClassIdSlots> markings_sized_by_class{};
  std::array<std::uint64_t, kClassIdSlots> markings_oversized_by_class{};
  void Add(const ExtractionCounters& o);
};

// Everything extracted from one mask.
struct FrameObservations {
  std::vector<MarkingObservation> markings;
  std::vector<LaneObservation> lanes;
  ExtractionCounters counters;
};

}  // namespace ipm_road_mapper
