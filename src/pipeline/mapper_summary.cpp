#include "ipm_road_mapper/pipeline/mapper_summary.h"

#include <cmath>
#include <sstream>

#include "ipm_road_mapper/core/backend/extrinsic_observability.h"
#include "ipm_road_mapper/core/frontend/class_size_check.h"
#include "ipm_road_mapper/core/geometry/rigid_transform.h"
#include "ipm_road_mapper/core/mapper/timing_series.h"

namespace ipm_road_mapper {

std::string MapperSummaryLines(const Mapper& mapper, const FrameAssembler& assembler,
                               const VectorMap& map) {
  const MapperCounters& c = mapper.counters();
  const FrameAssemblerCounters& a = assembler.counters();
  const ExtractionCounters& e = c.extraction;
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(2);
  s << "frames used: " << c.frames_used << "\nframes skipped: " << c.SkippedTotal() << "\n";
  for (const auto& [reason, count] : c.frames_skipped) s << "  " << reason << ": " << count << "\n";
  s << "odometry: " << a.odometry_received << " received, " << a.odometry_used << " used, "
    << a.bad_odometry << " bad, " << a.odometry_out_of_order
    << " out of order; time jumps: " << a.time_jumps << "\n"
    << "extraction: " << e.instances_seen << " instances; dropped: unknown class "
    << e.dropped_unknown_class << ", tiny " << e.dropped_tiny << ", border " << e.dropped_border
    << ", range " << e.dropped_range << ", degenerate " << e.dropped_degenerate
    << ", instance limit " << e.dropped_instance_limit << "; partial markings kept "
    << e.partial_markings << "\n"
    << "implausible: " << e.dropped_oversized << " oversized markings, " << e.dropped_wide_lane
    << " wide lanes (" << e.lane_runs_too_wide << " lane runs too wide), " << e.dropped_doubled_lane
    << " lanes doubling back (" << e.lane_rows_doubled
    << " lane rows of several runs), frames without observations: " << e.frames_too_many_instances
    << " too many instances, " << e.frames_too_much_coverage << " too much coverage ("
    << e.dropped_absurd_frame << " instances); odometry reordered " << a.odometry_reordered << "\n"
    << "sanity: " << c.sanity.area_instances << " hatched-area instances left out, "
    << c.sanity.lane_instances_split << " lane instances split into lines, "
    << c.sanity.lane_pieces_dropped << " lane pieces dropped (too small), "
    << c.sanity.lane_class_resolved << " lane classes resolved by evidence\n";
  for (const OversizedClass& suspect : MostlyOversizedClasses(e, mapper.classes())) {
    s << "warning: " << Describe(suspect) << "\n";
  }
  s << "map: " << map.markings.size() << " markings, " << map.lanes.size() << " lanes (created "
    << c.markings_created << " markings, " << c.lanes_created << " lanes; spurious dropped "
    << c.spurious_dropped << ", inconsistent " << c.markings_inconsistent << ", far-only dropped "
    << c.far_markings_dropped << ", restarted near " << c.far_markings_restarted
    << ", lanes merged " << c.lanes_merged << ", joined " << c.lanes_joined << " ("
    << c.lanes_joined_hidden_gap << " across a gap out of view)"
    << ", lane observations unused " << c.lane_observations_unused << ", near a lane "
    << c.lane_observations_near_lane << ", along a lane of another class "
    << c.lane_observations_other_class << ")\n"
    << BackendLine(mapper) << "\n"
    << CalibrationLine(mapper) << "\n"
    << FrontEndLine(mapper) << "\n";
  return s.str();
}

std::string BackendLine(const Mapper& mapper) {
  if (!mapper.options().backend.enabled) return "back end: disabled";
  const BackendStats stats = mapper.backend_stats();
  double total_s = 0.0;
  for (double t : stats.solve_times_s) total_s += t;
  const Eigen::Isometry3d change = mapper.T_base_cam_initial().inverse() * mapper.T_base_cam();
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(3);
  s << "back end: " << stats.submitted << " windows submitted, " << stats.solved << " solved, "
    << stats.dropped_queue_full << " dropped (queue full), " << stats.unusable << " unusable; "
    << "solve time " << total_s << " s total; results applied " << mapper.counters().results_applied
    << ", rejected " << mapper.counters().results_rejected << "; extrinsic moved "
    << RotationAngleBetween(mapper.T_base_cam_initial(), mapper.T_base_cam()) * 180.0 / M_PI
    << " deg, " << change.translation().norm() << " m";
  return s.str();
}

std::string CalibrationLine(const Mapper& mapper) {
  const Eigen::Matrix<double, 6, 1> sigma =
      mapper.T_base_cam_covariance().diagonal().cwiseMax(0.0).cwiseSqrt();
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(3);
  s << "calibration: sigma roll pitch yaw " << sigma(0) * 180.0 / M_PI << " "
    << sigma(1) * 180.0 / M_PI << " " << sigma(2) * 180.0 / M_PI << " deg, x y z " << sigma(3)
    << " " << sigma(4) << " " << sigma(5)
    << " m; observed: " << ObservedAxesText(mapper.extrinsic_observed())
    << "; extrinsic updates rejected " << mapper.counters().extrinsic_rejected
    << " (held-out frames explained worse); joint step held "
    << mapper.counters().joint_extrinsic_held << " unobserved directions";
  return s.str();
}

std::string FrontEndLine(const Mapper& mapper) {
  const FrontEndTiming& t = mapper.frontend_timing();
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(2);
  s << "front end: " << Quantile(t.total_ms, 0.5) << " ms/frame median, "
    << Quantile(t.total_ms, 0.95) << " ms p95, " << Quantile(t.total_ms, 1.0)
    << " ms max (extraction " << Quantile(t.extraction_ms, 0.5) << " ms median)";
  return s.str();
}

}  // namespace ipm_road_mapper
