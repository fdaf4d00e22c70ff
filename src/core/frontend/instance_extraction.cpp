#include "ipm_road_mapper/core/frontend/instance_extraction.h"

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "instance_extraction_runs.h"

namespace ipm_road_mapper {

using extraction::GeometryOutcome;
using extraction::InstanceStats;
using extraction::MaskRuns;
using extraction::Run;

namespace {

// Pixels tested at once by the background fast path of the scan.
constexpr int kSkipBlock = 32;

std::string CheckNonNegativeInt(const int& v) { return v >= 0 ? "" : "must be >= 0"; }

// "16UC1"-style name of an OpenCV matrix type.
std::string MatTypeName(int type) {
  static const char* const kDepthNames[] = {"8U", "8S", "16U", "16S", "32S", "32F", "64F", "16F"};
  return std::string(kDepthNames[CV_MAT_DEPTH(type)]) + "C" + std::to_string(CV_MAT_CN(type));
}

// True when none of the kSkipBlock pixels at `pixels` is foreground (a vectorizable max).
inline bool AllBackground(const std::uint16_t* pixels) {
  std::uint16_t max_value = 0;
  for (int k = 0; k < kSkipBlock; ++k) max_value = std::max(max_value, pixels[k]);
  return max_value < kInstanceIdFactor;
}

// True when some pixel of the instance lies within margin_px of the image border.
bool TouchesBorder(const InstanceStats& s, int width, int height, int margin_px) {
  return s.min_col < margin_px || s.min_row < margin_px || s.max_col > width - 1 - margin_px ||
         s.max_row > height - 1 - margin_px;
}

// Keeps at most `limit` candidates: the largest instances (ties: lower value first), so the
// choice is deterministic and the biggest (most informative) ones survive. The rest are
// counted. Leaves the kept candidates sorted by value.
void ApplyInstanceLimit(const MaskRuns& scan, int limit, std::vector<int>* slots,
                        ExtractionCounters* counters) {
  const auto by_value = [&scan](int a, int b) {
    return scan.instances[a].value < scan.instances[b].value;
  };
  if (limit >= 0 && static_cast<int>(slots->size()) > limit) {
    const auto larger_first = [&scan](int a, int b) {
      const InstanceStats& sa = scan.instances[a];
      const InstanceStats& sb = scan.instances[b];
      if (sa.pixel_count != sb.pixel_count) return sa.pixel_count > sb.pixel_count;
      return sa.value < sb.value;
    };
    std::nth_element(slots->begin(), slots->begin() + limit, slots->end(), larger_first);
    counters->dropped_instance_limit += slots->size() - limit;
    slots->resize(limit);
  }
  std::sort(slots->begin(), slots->end(), by_value);
}

// True (and counted) when the candidates `slots` are no real frame's: more than
// max_plausible_instances, or pixels covering more than max_coverage of the pixels below
// the horizon. Every candidate is then counted as dropped_absurd_frame.
bool IsAbsurdFrame(const MaskRuns& scan, const Ipm& ipm, const ExtractionOptions& options,
                   const std::vector<int>& slots, ExtractionCounters* counters) {
  if (slots.empty()) return false;
  if (static_cast<int>(slots.size()) > options.max_plausible_instances) {
    ++counters->frames_too_many_instances;
  } else {
    if (!extraction::CoversMoreThan(ipm, scan, slots, options.max_coverage)) return false;
    ++counters->frames_too_much_coverage;
  }
  counters->dropped_absurd_frame += slots.size();
  return true;
}

// The runs of the given instances, grouped by instance (row-major within each); *offsets
// gets each slot's first index in the result (-1 for slots not asked for).
std::vector<Run> GroupRuns(const MaskRuns& scan, const std::vector<int>& slots,
                           std::vector<int>* offsets) {
  offsets->assign(scan.instances.size(), -1);
  int total = 0;
  for (int slot : slots) {
    (*offsets)[slot] = total;
    total += scan.instances[slot].run_count;
  }
  std::vector<Run> grouped(total);
  std::vector<int> cursor = *offsets;
  for (const Run& run : scan.runs) {
    const int at = cursor[run.slot];
    if (at < 0) continue;
    grouped[at] = run;
    ++cursor[run.slot];
  }
  return grouped;
}

}  // namespace

namespace extraction {

MaskRuns ScanMask(const cv::Mat& mask) {
  MaskRuns scan;
  std::vector<int> slot_of_value(1 << 16, -1);
  scan.runs.reserve(std::size_t{8} * mask.rows);
  const int width = mask.cols;
  for (int row = 0; row < mask.rows; ++row) {
    const std::uint16_t* pixels = mask.ptr<std::uint16_t>(row);
    int col = 0;
    while (col < width) {
      while (col + kSkipBlock <= width && AllBackground(pixels + col)) col += kSkipBlock;
      while (col < width && pixels[col] < kInstanceIdFactor) ++col;
      if (col >= width) break;
      const std::uint16_t value = pixels[col];
      const int first_col = col;
      while (col < width && pixels[col] == value) ++col;
      const int last_col = col - 1;
      int& slot = slot_of_value[value];
      if (slot < 0) {
        slot = static_cast<int>(scan.instances.size());
        InstanceStats stats;
        stats.value = value;
        stats.min_col = first_col;
        stats.max_col = last_col;
        stats.min_row = row;  // rows are scanned top down: the first run is the top one
        scan.instances.push_back(stats);
      }
      InstanceStats& stats = scan.instances[slot];
      stats.pixel_count += last_col - first_col + 1;
      ++stats.run_count;
      stats.min_col = std::min(stats.min_col, first_col);
      stats.max_col = std::max(stats.max_col, last_col);
      stats.max_row = row;
      scan.runs.push_back(
          Run{static_cast<std::uint16_t>(row), static_cast<std::uint16_t>(first_col),
              static_cast<std::uint16_t>(last_col), static_cast<std::uint16_t>(slot)});
    }
  }
  return scan;
}

}  // namespace extraction

ExtractionOptions LoadExtractionOptions(OptionsReader reader) {
  ExtractionOptions o;
  reader.Read<int>("min_marking_pixels", &o.min_marking_pixels, CheckPositiveInt);
  reader.Read<int>("min_lane_pixels", &o.min_lane_pixels, CheckPositiveInt);
  reader.Read<int>("border_margin_px", &o.border_margin_px, CheckNonNegativeInt);
  reader.Read<int>("lane_row_step", &o.lane_row_step, CheckPositiveInt);
  reader.Read<int>("min_lane_points", &o.min_lane_points, [](const int& v) -> std::string {
    // One point has no direction: the lane association and fit need two.
    return v >= 2 ? "" : "must be >= 2 (got " + std::to_string(v) + ")";
  });
  reader.Read<int>("max_instances_per_frame", &o.max_instances_per_frame, CheckPositiveInt);
  reader.Read<double>("max_marking_range_m", &o.max_marking_range_m, CheckPositive);
  reader.Read<double>(
      "far_marking_range_m", &o.far_marking_range_m, [&o](const double& v) -> std::string {
        return v == 0.0 || v >= o.max_marking_range_m
                   ? ""
                   : "must be 0 (off) or >= max_marking_range_m (got " + std::to_string(v) + ")";
      });
  reader.Read<double>("min_rectangle_side_m", &o.min_rectangle_side_m, CheckNonNegative);
  reader.Read<int>("max_plausible_instances", &o.max_plausible_instances, CheckPositiveInt);
  reader.Read<double>("max_coverage", &o.max_coverage, [](const double& v) -> std::string {
    return v > 0.0 && v <= 1.0 ? "" : "must be in (0, 1] (got " + std::to_string(v) + ")";
  });
  reader.RejectUnknownKeys();
  return o;
}

std::string ValidateMask(const cv::Mat& mask, int expected_width, int expected_height) {
  const std::string camera_size =
      std::to_string(expected_width) + "x" + std::to_string(expected_height);
  if (mask.empty()) return "mask is empty, expected a 16UC1 (mono16) image of " + camera_size;
  if (mask.dims != 2) return "mask has " + std::to_string(mask.dims) + " dimensions, expected 2";
  if (mask.type() != CV_16UC1) {
    return "mask type is " + MatTypeName(mask.type()) + ", expected 16UC1 (mono16)";
  }
  if (mask.cols > extraction::kMaxMaskSide || mask.rows > extraction::kMaxMaskSide) {
    return "mask is " + std::to_string(mask.cols) + "x" + std::to_string(mask.rows) +
           ", larger than the supported " + std::to_string(extraction::kMaxMaskSide) + " px a side";
  }
  if (mask.cols != expected_width || mask.rows != expected_height) {
    return "mask is " + std::to_string(mask.cols) + "x" + std::to_string(mask.rows) +
           ", camera is " + camera_size;
  }
  return "";
}

FrameObservations ExtractObservations(const cv::Mat& mask, const ClassTable& classes,
                                      const Ipm& ipm, const IpmErrorModel& error_model,
                                      const ExtractionOptions& options) {
  FrameObservations observations;
  // Callers validate first; an unusable mask still must not crash the front end.
  if (mask.empty() || mask.dims != 2 || mask.type() != CV_16UC1 ||
      mask.cols > extraction::kMaxMaskSide || mask.rows > extraction::kMaxMaskSide) {
    return observations;
  }
  ExtractionCounters& counters = observations.counters;

  const MaskRuns scan = extraction::ScanMask(mask);
  counters.instances_seen = scan.instances.size();

  // Cheap rejections from the scan's statistics, before any per-instance work.
  std::vector<int> slots, counted;  // candidates; those the frame statistics count
  std::vector<bool> is_lane(scan.instances.size(), false);
  for (int slot = 0; slot < static_cast<int>(scan.instances.size()); ++slot) {
    const InstanceStats& stats = scan.instances[slot];
    const ClassInfo* info = classes.Find(ClassIdOf(stats.value));
    if (info == nullptr) {
      ++counters.dropped_unknown_class;
      continue;
    }
    is_lane[slot] = info->kind == ElementKind::kLane;
    const int min_pixels = is_lane[slot] ? options.min_lane_pixels : options.min_marking_pixels;
    if (stats.pixel_count < min_pixels) {
      ++counters.dropped_tiny;
      continue;
    }
    slots.push_back(slot);
    // A marking cut by the border (a crossing wider than the view) is a partial view, no
    // sign of a network gone wrong: the frame statistics leave it out, as they always did.
    if (is_lane[slot] ||
        !TouchesBorder(stats, mask.cols, mask.rows, std::max(options.border_margin_px, 0))) {
      counted.push_back(slot);
    }
  }
  if (IsAbsurdFrame(scan, ipm, options, counted, &counters)) {
    counters.dropped_absurd_frame += slots.size() - counted.size();
    return observations;
  }
  ApplyInstanceLimit(scan, options.max_instances_per_frame, &slots, &counters);

  std::vector<int> offsets;
  const std::vector<Run> grouped = GroupRuns(scan, slots, &offsets);
  for (int slot : slots) {
    const InstanceStats& stats = scan.instances[slot];
    const Run* runs = grouped.data() + offsets[slot];
    const ClassInfo& class_info = *classes.Find(ClassIdOf(stats.value));
    GeometryOutcome outcome;
    if (is_lane[slot]) {
      LaneObservation lane;
      lane.class_id = ClassIdOf(stats.value);
      lane.instance_value = stats.value;
      lane.pixel_count = stats.pixel_count;
      outcome =
          extraction::ExtractLane(runs, stats.run_count, class_info, ipm, error_model, options,
                                  &lane, &counters.lane_runs_too_wide, &counters.lane_rows_doubled);
      if (outcome == GeometryOutcome::kOk) observations.lanes.push_back(std::move(lane));
    } else {
      MarkingObservation marking;
      marking.class_id = ClassIdOf(stats.value);
      marking.instance_value = stats.value;
      marking.pixel_count = stats.pixel_count;
      outcome = extraction::ExtractMarking(runs, stats.run_count, mask, stats.value, classes, ipm,
                                           error_model, options, &marking);
      if (outcome == GeometryOutcome::kOk || outcome == GeometryOutcome::kTruncated ||
          outcome == GeometryOutcome::kOversized) {
        ++counters.markings_sized_by_class[marking.class_id];
        if (outcome == GeometryOutcome::kOversized) {
          ++counters.markings_oversized_by_class[marking.class_id];
        }
      }
      if (outcome == GeometryOutcome::kOk) {
        if (!marking.Complete()) ++counters.partial_markings;
        observations.markings.push_back(std::move(marking));
      }
    }
    if (outcome == GeometryOutcome::kRange) ++counters.dropped_range;
    if (outcome == GeometryOutcome::kDegenerate) ++counters.dropped_degenerate;
    if (outcome == GeometryOutcome::kOversized) ++counters.dropped_oversized;
    if (outcome == GeometryOutcome::kTooWide) ++counters.dropped_wide_lane;
    if (outcome == GeometryOutcome::kDoublesBack) ++counters.dropped_doubled_lane;
    if (outcome == GeometryOutcome::kTruncated) ++counters.dropped_border;
  }
  return observations;
}

}  // namespace ipm_road_mapper
