#include "ipm_road_mapper/pipeline/debug_overlay.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <exception>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "ipm_road_mapper/core/frontend/instance_extraction.h"
#include "ipm_road_mapper/core/geometry/ipm.h"
#include "ipm_road_mapper/core/geometry/rigid_transform.h"
#include "ipm_road_mapper/core/map/lane_samples.h"

namespace ipm_road_mapper {
namespace {

const cv::Scalar kMapColor(0, 220, 0);         // green (BGR)
const cv::Scalar kLaidColor(160, 160, 160);    // grey: a lane stretch no pixel measured
const cv::Scalar kMeasuredColor(255, 0, 255);  // magenta
const cv::Scalar kResidualColor(0, 255, 255);  // yellow
constexpr double kMinDepthM = 0.5;             // closer points are not drawn
constexpr double kMaxElementRangeM = 80.0;     // farther map elements are not projected
constexpr double kMarkingMatchGateM = 3.0;     // measured vs mapped center, on the ground
constexpr double kLaneMatchGatePx = 80.0;
constexpr double kLaneSampleSpacingM = 0.5;

// Map points -> pixels for one frame.
class FrameProjector {
 public:
  FrameProjector(const OverlayFrame& frame)
      : camera_(frame.camera), T_cam_map_((frame.T_map_base * frame.T_base_cam).inverse()) {}

  bool Project(const Eigen::Vector3d& p_map, Eigen::Vector2d* uv) const {
    const Eigen::Vector3d p_cam = T_cam_map_ * p_map;
    if (p_cam.z() < kMinDepthM || !camera_.Project(p_cam, uv)) return false;
    // Far outside the image the distortion model folds back: do not draw there.
    const double margin = 0.5 * std::max(camera_.width(), camera_.height());
    return uv->x() > -margin && uv->y() > -margin && uv->x() < camera_.width() + margin &&
           uv->y() < camera_.height() + margin;
  }

 private:
  PinholeCamera camera_;
  Eigen::Isometry3d T_cam_map_;
};

cv::Point ToCv(const Eigen::Vector2d& uv) {
  return cv::Point(static_cast<int>(std::lround(uv.x())), static_cast<int>(std::lround(uv.y())));
}

// Line width that stays visible when the image is shown scaled down (rviz's image panel).
int Thickness(const cv::Mat& canvas) { return std::max(2, canvas.cols / 400); }
int ThinThickness(const cv::Mat& canvas) { return std::max(1, Thickness(canvas) - 1); }

cv::Mat Background(const OverlayFrame& frame) {
  const cv::Size size(frame.camera.width, frame.camera.height);
  cv::Mat canvas;
  if (!frame.image.empty() && frame.image.size() == size) {
    if (frame.image.type() == CV_8UC3) {
      canvas = frame.image.clone();
    } else if (frame.image.type() == CV_8UC1) {
      cv::cvtColor(frame.image, canvas, cv::COLOR_GRAY2BGR);
    }
  }
  if (canvas.empty()) {
    canvas = cv::Mat(size, CV_8UC3, cv::Scalar(0, 0, 0));
    if (!frame.mask.empty() && frame.mask.size() == size && frame.mask.type() == CV_16UC1) {
      canvas.setTo(cv::Scalar(90, 90, 90), frame.mask >= kInstanceIdFactor);
    }
  }
  return canvas;
}

// Distance from p to segment ab.
double SegmentDistance(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                       const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double t =
      ab.squaredNorm() > 0 ? std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0) : 0.0;
  return (a + t * ab - p).norm();
}

struct ProjectedMarking {
  const MapMarking* marking;
  std::array<Eigen::Vector2d, 4> corners_uv;
};

using Polyline = std::vector<Eigen::Vector2d>;

void DrawMarkings(const VectorMap& map, const FrameProjector& projector,
                  const Eigen::Vector3d& vehicle, cv::Mat* canvas,
                  std::vector<ProjectedMarking>* projected) {
  for (const MapMarking& marking : map.markings) {
    if ((marking.Center() - vehicle).head<2>().norm() > kMaxElementRangeM) continue;
    ProjectedMarking p{&marking, {}};
    bool ok = true;
    for (int i = 0; i < 4 && ok; ++i)
      ok = projector.Project(marking.corners_map[i], &p.corners_uv[i]);
    if (!ok) continue;
    for (int i = 0; i < 4; ++i) {
      cv::line(*canvas, ToCv(p.corners_uv[i]), ToCv(p.corners_uv[(i + 1) % 4]), kMapColor,
               Thickness(*canvas), cv::LINE_AA);
    }
    projected->push_back(p);
  }
}

void DrawLanes(const VectorMap& map, const FrameProjector& projector,
               const Eigen::Vector3d& vehicle, cv::Mat* canvas, std::vector<Polyline>* lanes) {
  for (const MapLane& lane : map.lanes) {
    LaneSamples samples;
    try {
      samples =
          SampleLane(lane.control_points_map, UnmeasuredPointFlags(lane), kLaneSampleSpacingM);
    } catch (const std::exception&) {
      continue;
    }
    Polyline line;
    for (std::size_t k = 0; k < samples.points.size(); ++k) {
      const Eigen::Vector3d& p = samples.points[k];
      Eigen::Vector2d uv;
      if ((p - vehicle).head<2>().norm() > kMaxElementRangeM || !projector.Project(p, &uv)) {
        if (line.size() >= 2) lanes->push_back(line);
        line.clear();
        continue;
      }
      if (!line.empty()) {
        cv::line(*canvas, ToCv(line.back()), ToCv(uv),
                 samples.unmeasured[k] ? kLaidColor : kMapColor, Thickness(*canvas), cv::LINE_AA);
      }
      line.push_back(uv);
    }
    if (line.size() >= 2) lanes->push_back(line);
  }
}

// Measured markings: corners, outline, and lines to the matched mapped marking's corners.
void DrawMeasuredMarkings(const FrameObservations& measured,
                          const std::vector<ProjectedMarking>& projected, const OverlayFrame& frame,
                          cv::Mat* canvas, OverlayStats* stats) {
  double residual_sum = 0.0;
  int residual_count = 0;
  for (const MarkingObservation& obs : measured.markings) {
    ++stats->markings_measured;
    for (int i = 0; i < 4; ++i) {
      cv::line(*canvas, ToCv(obs.corners_uv[i]), ToCv(obs.corners_uv[(i + 1) % 4]), kMeasuredColor,
               ThinThickness(*canvas), cv::LINE_AA);
      cv::circle(*canvas, ToCv(obs.corners_uv[i]), Thickness(*canvas) + 2, kMeasuredColor, -1,
                 cv::LINE_AA);
    }
    Eigen::Vector3d center_base = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& c : obs.corners_base) center_base += 0.25 * c;
    const Eigen::Vector3d center_map = frame.T_map_base * center_base;
    const ProjectedMarking* best = nullptr;
    double best_distance = kMarkingMatchGateM;
    for (const ProjectedMarking& p : projected) {
      if (p.marking->class_id != obs.class_id) continue;
      const double d = (p.marking->Center() - center_map).head<2>().norm();
      if (d < best_distance) {
        best_distance = d;
        best = &p;
      }
    }
    if (!best) continue;
    // Best cyclic order of the corners (the map keeps the order it was created with).
    int best_shift = 0;
    double best_sum = std::numeric_limits<double>::infinity();
    for (int shift = 0; shift < 4; ++shift) {
      double sum = 0.0;
      for (int i = 0; i < 4; ++i) {
        sum += (obs.corners_uv[i] - best->corners_uv[(i + shift) % 4]).norm();
      }
      if (sum < best_sum) {
        best_sum = sum;
        best_shift = shift;
      }
    }
    for (int i = 0; i < 4; ++i) {
      cv::line(*canvas, ToCv(obs.corners_uv[i]), ToCv(best->corners_uv[(i + best_shift) % 4]),
               kResidualColor, ThinThickness(*canvas), cv::LINE_AA);
    }
    ++stats->marking_matches;
    residual_sum += best_sum;
    residual_count += 4;
  }
  if (residual_count > 0) stats->mean_corner_residual_px = residual_sum / residual_count;
}

// Measured lane pixels, and a line from each to the nearest projected lane within the gate.
void DrawMeasuredLanes(const FrameObservations& measured, const std::vector<Polyline>& lanes,
                       cv::Mat* canvas, OverlayStats* stats) {
  double residual_sum = 0.0;
  for (const LaneObservation& obs : measured.lanes) {
    for (const LanePoint& point : obs.points) {
      ++stats->lane_points_measured;
      cv::circle(*canvas, ToCv(point.uv), Thickness(*canvas) + 1, kMeasuredColor, -1, cv::LINE_AA);
      double best = kLaneMatchGatePx;
      Eigen::Vector2d best_point = point.uv;
      for (const Polyline& line : lanes) {
        for (std::size_t i = 0; i + 1 < line.size(); ++i) {
          const double d = SegmentDistance(point.uv, line[i], line[i + 1]);
          if (d < best) {
            best = d;
            const Eigen::Vector2d ab = line[i + 1] - line[i];
            const double t =
                ab.squaredNorm() > 0
                    ? std::clamp((point.uv - line[i]).dot(ab) / ab.squaredNorm(), 0.0, 1.0)
                    : 0.0;
            best_point = line[i] + t * ab;
          }
        }
      }
      if (best < kLaneMatchGatePx) {
        cv::line(*canvas, ToCv(point.uv), ToCv(best_point), kResidualColor, ThinThickness(*canvas),
                 cv::LINE_AA);
        ++stats->lane_point_matches;
        residual_sum += best;
      }
    }
  }
  if (stats->lane_point_matches > 0) {
    stats->mean_lane_residual_px = residual_sum / stats->lane_point_matches;
  }
}

void DrawLegend(const OverlayStats& stats, cv::Mat* canvas) {
  const double scale = std::max(0.6, canvas->cols / 1000.0);
  const int step = static_cast<int>(30 * scale);
  auto text = [&](int row, const std::string& s, const cv::Scalar& color) {
    const cv::Point at(10, step * (row + 1));
    cv::putText(*canvas, s, at, cv::FONT_HERSHEY_SIMPLEX, 0.7 * scale, cv::Scalar(0, 0, 0), 5,
                cv::LINE_AA);
    cv::putText(*canvas, s, at, cv::FONT_HERSHEY_SIMPLEX, 0.7 * scale, color, 2, cv::LINE_AA);
  };
  char line[160];
  std::snprintf(line, sizeof(line), "map projection: %d markings, %d lane pieces",
                stats.markings_projected, stats.lanes_projected);
  text(0, line, kMapColor);
  std::snprintf(line, sizeof(line), "measured: %d markings, %d lane pixels",
                stats.markings_measured, stats.lane_points_measured);
  text(1, line, kMeasuredColor);
  std::snprintf(line, sizeof(line), "residual: corners %.1f px (%d), lanes %.1f px (%d)",
                stats.mean_corner_residual_px, stats.marking_matches, stats.mean_lane_residual_px,
                stats.lane_point_matches);
  text(2, line, kResidualColor);
}

}  // namespace

FrameObservations MeasureFrame(const cv::Mat& mask, const CameraIntrinsics& camera,
                               const Eigen::Isometry3d& T_base_cam, const ClassTable& classes,
                               const MapperOptions& options) {
  const PinholeCamera pinhole(camera);
  if (!pinhole.Validate().empty() || !ValidateMask(mask, camera.width, camera.height).empty() ||
      !IsValidTransform(T_base_cam)) {
    return FrameObservations();
  }
  const Ipm ipm(pinhole, T_base_cam, options.ipm.max_range_m);
  return ExtractObservations(mask, classes, ipm, options.ipm.error_model, options.extraction);
}

cv::Mat DrawDebugOverlay(const OverlayFrame& frame, const FrameObservations& measured,
                         const VectorMap& map, OverlayStats* stats_out) {
  OverlayStats stats;
  const PinholeCamera camera(frame.camera);
  if (!camera.Validate().empty() || frame.camera.width <= 0 || frame.camera.height <= 0 ||
      frame.camera.width > 20000 || frame.camera.height > 20000) {
    cv::Mat blank(480, 640, CV_8UC3, cv::Scalar(0, 0, 0));
    cv::putText(blank, "debug overlay: unusable camera_info", cv::Point(10, 30),
                cv::FONT_HERSHEY_SIMPLEX, 0.7, cv::Scalar(0, 0, 255), 2);
    if (stats_out) *stats_out = stats;
    return blank;
  }
  cv::Mat canvas = Background(frame);
  if (!IsValidTransform(frame.T_map_base) || !IsValidTransform(frame.T_base_cam)) {
    cv::putText(canvas, "debug overlay: invalid pose", cv::Point(10, 30), cv::FONT_HERSHEY_SIMPLEX,
                0.7, cv::Scalar(0, 0, 255), 2);
    if (stats_out) *stats_out = stats;
    return canvas;
  }
  const FrameProjector projector(frame);
  const Eigen::Vector3d vehicle = frame.T_map_base.translation();
  std::vector<ProjectedMarking> projected;
  DrawMarkings(map, projector, vehicle, &canvas, &projected);
  std::vector<Polyline> lanes;
  DrawLanes(map, projector, vehicle, &canvas, &lanes);
  stats.markings_projected = static_cast<int>(projected.size());
  stats.lanes_projected = static_cast<int>(lanes.size());
  DrawMeasuredMarkings(measured, projected, frame, &canvas, &stats);
  DrawMeasuredLanes(measured, lanes, &canvas, &stats);
  DrawLegend(stats, &canvas);
  if (stats_out) *stats_out = stats;
  return canvas;
}

}  // namespace ipm_road_mapper
