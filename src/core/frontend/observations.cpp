#include "ipm_road_mapper/core/frontend/observations.h"

namespace ipm_road_mapper {

void ExtractionCounters::Add(const ExtractionCounters& o) {
  instances_seen += o.instances_seen;
  dropped_unknown_class += o.dropped_unknown_class;
  dropped_tiny += o.dropped_tiny;
  dropped_border += o.dropped_border;
  partial_markings += o.partial_markings;
  dropped_range += o.dropped_range;
  dropped_degenerate += o.dropped_degenerate;
  dropped_instance_limit += o.dropped_instance_limit;
  dropped_oversized += o.dropped_oversized;
  dropped_wide_lane += o.dropped_wide_lane;
  dropped_doubled_lane += o.dropped_doubled_lane;
  lane_rows_doubled += o.lane_rows_doubled;
  dropped_absurd_frame += o.dropped_absurd_frame;
  lane_runs_too_wide += o.lane_runs_too_wide;
  frames_too_many_instances += o.frames_too_many_instances;
  frames_too_much_coverage += o.frames_too_much_coverage;
  for (int i = 0; i < kClassIdSlots; ++i) {
    markings_sized_by_class[i] += o.markings_sized_by_class[i];
    markings_oversized_by_class[i] += o.markings_oversized_by_class[i];
  }
}

}  // namespace ipm_road_mapper
