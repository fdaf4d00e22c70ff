// The mask's instances made sane before extraction, for masks from a real network: area
// classes (hatched areas) left out of the map and counted; a lane instance that holds
// several lines (two lines side by side merged into one instance, a line and a stripe
// crossing it) split into one instance per line, the pieces too small to be a line dropped; and a
// lane instance whose class disagrees with what the last frames saw at the same place (solid <->
// dashed flicker) given the class the evidence there holds. Each is counted (MaskSanityCounters:
// the summary's `sanity:` line and the diagnostics).
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <deque>
#include <opencv2/core.hpp>
#include <vector>

#include "ipm_road_mapper/core/frontend/class_table.h"
#include "ipm_road_mapper/core/geometry/ipm.h"
#include "ipm_road_mapper/core/io/yaml_options.h"

namespace ipm_road_mapper {

// Config section `sanity`.
struct MaskSanityOptions {
  // Classes that are areas, not map elements (the segmenter's hatched_area): their pixels
  // are removed from the mask and each instance counted (hatched areas are not mapped).
  std::vector<int> area_class_ids{30};
  bool split_lanes = true;    // a lane instance's pieces that are no one line split
  int min_piece_pixels = 0;   // smaller pieces of a lane instance are dropped (0: none)
  int min_line_pixels = 200;  // a smaller piece is never split off as a line of its own
  // Two pieces are two lines when side by side: directions within collinear_max_turn_deg,
  // overlapping along them, apart across by more than collinear_max_offset_m (+5 % of their
  // distance; two lines merged into one instance are a lane's width apart); or when their
  // directions differ by more than split_min_turn_deg (a line and a stripe merged).
  double collinear_max_turn_deg = 20.0;
  double collinear_max_offset_m = 1.0;
  double split_min_turn_deg = 45.0;
  int flicker_memory_frames = 10;  // lane class evidence of this many frames (0: off)
  double flicker_radius_m = 0.5;   // evidence this near an instance's points counts
  double flicker_majority = 2.0;   // another class with this many times the votes wins
  int flicker_min_votes = 20;      // ... and at least this many points of evidence
};

// Reads the section; throws OptionsError naming a bad or unknown key.
MaskSanityOptions LoadMaskSanityOptions(OptionsReader reader);

struct MaskSanityCounters {
  std::uint64_t area_instances = 0;        // hatched-area instances left out of the map
  std::uint64_t lane_instances_split = 0;  // lane instances that held several lines
  std::uint64_t lane_pieces_dropped = 0;   // pieces of lane instances too small to be a line
  std::uint64_t lane_class_resolved = 0;   // lane instances given the class the evidence holds

  void Add(const MaskSanityCounters& other);
};

class MaskSanity {
 public:
  MaskSanity(const MaskSanityOptions& options, const ClassTable* classes)
      : options_(options), classes_(classes) {}

  // The sane mask: `mask` itself when nothing changes, else a changed copy. `ipm` maps the
  // frame's pixels to the ground of base_link, T_map_base places them in the map (the class
  // evidence of the last frames is kept there).
  cv::Mat Clean(const cv::Mat& mask, const Ipm& ipm, const Eigen::Isometry3d& T_map_base,
                MaskSanityCounters* counters);

  void Reset() { memory_.clear(); }

 private:
  // A point of lane evidence in the map (x, y) with its class.
  struct Vote {
    Eigen::Vector2f xy;
    int class_id;
  };

  // The class of one line of an instance of `class_id` (its ground points in the map): the
  // other lane class when the last frames' evidence near those points holds
  // flicker_majority times more of it (counted), else class_id.
  int ResolveClass(const std::vector<Eigen::Vector2f>& points_map, int class_id,
                   MaskSanityCounters* counters) const;

  MaskSanityOptions options_;
  const ClassTable* classes_;
  std::deque<std::vector<Vote>> memory_;  // one entry per frame, newest last
};

}  // namespace ipm_road_mapper
