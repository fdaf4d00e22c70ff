// Per-frame rendering of a synthetic drive: the instance mask with segmentation noise, and
// the gray image.
#include <algorithm>
#include <cmath>
#include <numeric>
#include <opencv2/core.hpp>

#include "ipm_road_mapper/sim/drive_simulator.h"
#include "ipm_road_mapper/sim/instance_split.h"
#include "ipm_road_mapper/sim/occluder.h"
#include "ipm_road_mapper/sim/sim_random.h"

namespace ipm_road_mapper {
namespace sim {
namespace {

// Gray levels of the image.
constexpr int kSkyGray = 185;
constexpr int kTerrainGray = 72;
constexpr int kShoulderGray = 105;
constexpr int kAsphaltGray = 88;
constexpr int kWhitePaintGray = 228;
constexpr int kYellowPaintGray = 168;
constexpr int kVehicleGray = 40;
constexpr double kRoadQuadM = 2.0;

// One instance being drawn: its mask value, the union of its fill boxes, where it came from.
struct Pending {
  RenderedInstance instance;
  cv::Rect roi;
  bool drawn = false;
};

int PaintGray(PaintColor color) {
  return color == PaintColor::kYellow ? kYellowPaintGray : kWhitePaintGray;
}

bool Overlaps(double a0, double a1, double b0, double b1) { return a0 <= b1 && b0 <= a1; }

// Fills the projection of every occluder box present at (s_cam, t_s) with `value`, or, with
// `instance_class_id` > 0, occluder i with that class's instance value (i + 1).
void FillOccluders(const std::vector<OccluderOptions>& occluders, const RoadModel& road,
                   const Eigen::Isometry3d& T_cam_map, double s_cam, double t_s,
                   const FrustumProjector& projector, int value, int instance_class_id,
                   cv::Mat* image, FillRule rule = FillRule::kOpenCvFillPoly) {
  std::vector<Eigen::Vector3d> face_cam;
  for (std::size_t i = 0; i < occluders.size(); ++i) {
    const OccluderOptions& occluder = occluders[i];
    if (instance_class_id > 0) {
      value = instance_class_id * kInstanceIdFactor + static_cast<int>(i) + 1;
    }
    for (const auto& face_map : OccluderFaces(road, occluder, s_cam, t_s)) {
      face_cam.clear();
      for (const Eigen::Vector3d& p_map : face_map) face_cam.push_back(T_cam_map * p_map);
      FillPixelPolygon(projector.Project(face_cam), value, image, rule);
    }
  }
}

}  // namespace

void DriveSimulator::RenderMask(const FrameContext& context, bool noise, SimFrame* frame) {
  const SegmentationNoiseOptions& seg = scenario_.segmentation;
  SimRandom random = SimRandom::ForStream(seed_, RandomStream::kSegmentation, context.index);
  // Draws happen in a fixed order, whatever is visible, so frames are independent.
  std::array<double, 8> wave_randoms;
  for (double& r : wave_randoms) r = random.Uniform();
  const JitterField jitter =
      noise ? JitterField(seg.boundary_jitter_px, seg.jitter_wavelength_px, wave_randoms)
            : JitterField();
  const int blobs = random.Poisson(seg.spurious_blobs_per_frame);
  const auto& lines = world_.lane_lines();
  const auto& markings = world_.markings();
  std::vector<bool> missed(lines.size() + markings.size());
  for (std::size_t i = 0; i < missed.size(); ++i) {
    missed[i] = random.Bernoulli(seg.missed_instance_prob) && noise;
  }
  // Candidates: every lane line, the markings in the window, the blobs.
  const double s0 = context.s_cam - 2.0, s1 = context.s_cam + 1.2 * seg.range_m + 5.0;
  std::vector<int> window_markings;
  for (const SimMarking& m : markings) {
    if (Overlaps(m.s_min, m.s_max, s0, s1)) window_markings.push_back(m.id - 1);
  }
  const int n_blobs = noise ? blobs : 0;
  const int candidates =
      std::min<int>(kInstanceIdFactor - 1, lines.size() + window_markings.size() + n_blobs);
  // Random instance indices (a network's indices carry no identity across frames).
  std::vector<int> indices(candidates);
  std::iota(indices.begin(), indices.end(), 1);
  for (int i = candidates - 1; i > 0; --i) std::swap(indices[i], indices[random.UniformInt(0, i)]);

  frame->mask = cv::Mat::zeros(camera_.height(), camera_.width(), CV_16UC1);
  std::vector<Pending> pending;
  std::vector<Eigen::Vector2d> uv;
  auto draw = [&](const std::vector<Eigen::Vector2d>& polygon_uv, Pending* p) {
    std::vector<Eigen::Vector2d> jittered = polygon_uv;
    if (jitter.active()) {
      for (Eigen::Vector2d& q : jittered) q = jitter.Apply(q);
    }
    const cv::Rect box =
        FillPixelPolygon(jittered, p->instance.value, &frame->mask, seg.mask_rasterizer);
    if (box.empty()) return;
    p->roi = p->drawn ? (p->roi | box) : box;
    p->drawn = true;
  };
  auto next_value = [&](int class_id) {
    const int slot = static_cast<int>(pending.size());
    return slot < candidates ? class_id * kInstanceIdFactor + indices[slot] : -1;
  };
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const SimLaneLine& line = lines[i];
    Pending p;
    p.instance = {next_value(line.class_id), RenderedInstance::Source::kLane, line.id, 0};
    if (!missed[i] && p.instance.value > 0) {
      auto it =
          std::lower_bound(line.pieces.begin(), line.pieces.end(), s0,
                           [](const SurfacePolygon& piece, double s) { return piece.s_max < s; });
      for (; it != line.pieces.end() && it->s_min <= s1; ++it) {
        if (ToPixels(*it, context, mask_projector_, &uv)) draw(uv, &p);
      }
    }
    pending.push_back(p);
  }
  for (int index : window_markings) {
    const SimMarking& m = markings[index];
    Pending p;
    p.instance = {next_value(m.class_id), RenderedInstance::Source::kMarking, m.id, 0};
    if (!missed[lines.size() + index] && p.instance.value > 0) {
      for (const SurfacePolygon& component : m.components) {
        if (ToPixels(component, context, mask_projector_, &uv)) draw(uv, &p);
      }
    }
    pending.push_back(p);
  }
  // Vehicles ahead hide the paint behind them: background in the mask, or their own
  // instances when the segmentation labels them.
  FillOccluders(scenario_.occluders, world_.road(), context.T_cam_map, context.s_cam,
                context.index / scenario_.camera.rate_hz, mask_projector_, 0, seg.occluder_class_id,
                &frame->mask, seg.mask_rasterizer);
  for (int b = 0; b < n_blobs; ++b) {
    // A small star-shaped polygon of a random marking class below the image's middle.
    const int class_id = marking_class_ids_[random.UniformInt(0, marking_class_ids_.size() - 1)];
    Pending p;
    p.instance = {next_value(class_id), RenderedInstance::Source::kSpurious, 0, 0};
    const Eigen::Vector2d center(random.Uniform(0.0, camera_.width()),
                                 random.Uniform(0.55, 1.0) * camera_.height());
    const double radius = random.Uniform(4.0, 20.0);
    const int vertices = random.UniformInt(5, 8);
    std::vector<Eigen::Vector2d> blob;
    for (int v = 0; v < vertices; ++v) {
      const double angle = 2.0 * M_PI * (v + random.Uniform(0.0, 0.5)) / vertices;
      blob.push_back(center + radius * random.Uniform(0.6, 1.0) *
                                  Eigen::Vector2d(std::cos(angle), std::sin(angle)));
    }
    if (p.instance.value > 0) draw(blob, &p);
    pending.push_back(p);
  }
  // Keep instances with enough pixels left after all drawing; erase the rest. A kept lane or
  // marking instance may be split in two (its own stream, drawn for every candidate in
  // order); the second part takes the next index above the candidates'.
  SimRandom split_random = SimRandom::ForStream(seed_, RandomStream::kSplit, context.index);
  const int min_pixels = std::max(1, seg.min_instance_pixels);
  int next_index = candidates + 1;
  std::vector<RenderedInstance> split_parts;
  for (Pending& p : pending) {
    const bool split = split_random.Bernoulli(seg.split_instance_prob) && noise &&
                       p.instance.source != RenderedInstance::Source::kSpurious;
    const double angle = split_random.Uniform(0.0, M_PI);
    if (!p.drawn) continue;
    cv::Mat roi = frame->mask(p.roi);
    const cv::Mat hit = roi == p.instance.value;
    p.instance.pixels = cv::countNonZero(hit);
    if (p.instance.pixels < min_pixels) {
      if (p.instance.pixels > 0) roi.setTo(0, hit);
      continue;
    }
    if (split && next_index < kInstanceIdFactor) {
      const int new_value = (p.instance.value / kInstanceIdFactor) * kInstanceIdFactor + next_index;
      const int moved = SplitInstance(p.instance.value, new_value,
                                      Eigen::Vector2d(std::cos(angle), std::sin(angle)), &roi);
      if (moved >= min_pixels && p.instance.pixels - moved >= min_pixels) {
        RenderedInstance part = p.instance;
        part.value = new_value;
        part.pixels = moved;
        p.instance.pixels -= moved;
        split_parts.push_back(part);
        ++next_index;
      } else if (moved > 0) {
        roi.setTo(p.instance.value, roi == new_value);  // a sliver: keep the instance whole
      }
    }
    frame->instances.push_back(p.instance);
  }
  frame->instances.insert(frame->instances.end(), split_parts.begin(), split_parts.end());
}

void DriveSimulator::RenderImage(const FrameContext& context, SimFrame* frame) const {
  cv::Mat image(camera_.height(), camera_.width(), CV_8UC1, cv::Scalar(kTerrainGray));
  const Eigen::Isometry3d T_map_cam = context.T_cam_map.inverse();
  // Sky: everything above the horizon (directions with a positive map z component), as a
  // polygon at unit depth through the projector so the horizon follows the distortion.
  const Eigen::Vector3d up_cam = T_map_cam.linear().transpose() * Eigen::Vector3d::UnitZ();
  if (std::abs(up_cam.y()) > 1e-6) {
    auto horizon_y = [&](double x) { return -(up_cam.x() * x + up_cam.z()) / up_cam.y(); };
    std::vector<Eigen::Vector3d> sky = {{-3.0, horizon_y(-3.0), 1.0},
                                        {3.0, horizon_y(3.0), 1.0},
                                        {3.0, -30.0, 1.0},
                                        {-3.0, -30.0, 1.0}};
    if (up_cam.y() > 0.0) {  // upside down: the sky is below the horizon line
      sky[2].y() = sky[3].y() = 30.0;
    }
    FillPixelPolygon(image_projector_.Project(sky), kSkyGray, &image);
  }
  // Road surface, far to near, in quads with a ground-anchored shade (asphalt patches).
  const RoadModel& road = world_.road();
  const double l_right = road.LineOffset(0) - 0.4;
  const double l_left = road.LineOffset(road.options().lanes) + 0.4;
  const double shoulder = road.options().shoulder_width_m;
  const double far_s = context.s_cam + scenario_.camera.image_range_m + 5.0;
  const int q0 = static_cast<int>(std::floor((context.s_cam - 2.0) / kRoadQuadM));
  const int q1 = static_cast<int>(std::ceil(far_s / kRoadQuadM));
  std::vector<Eigen::Vector3d> quad(4);
  for (int q = q1; q >= q0; --q) {
    const double sa = q * kRoadQuadM, sb = sa + kRoadQuadM;
    const int shade = static_cast<int>(SplitMix64(static_cast<std::uint64_t>(q + 100000)) % 9) - 4;
    // The asphalt in two quads either side of a crown's ridge (flat quads would cut it).
    const double ridge = road.crown() > 0.0
                             ? std::clamp(road.options().surface.crown_offset_m, l_right, l_left)
                             : l_right;
    for (const auto& [la, lb, gray] :
         {std::tuple<double, double, int>{l_right - shoulder, l_right, kShoulderGray},
          {l_right, ridge, kAsphaltGray + shade},
          {ridge, l_left, kAsphaltGray + shade},
          {l_left, l_left + shoulder, kShoulderGray}}) {
      if (lb <= la) continue;
      quad[0] = context.T_cam_map * road.SurfacePoint(sa, la);
      quad[1] = context.T_cam_map * road.SurfacePoint(sb, la);
      quad[2] = context.T_cam_map * road.SurfacePoint(sb, lb);
      quad[3] = context.T_cam_map * road.SurfacePoint(sa, lb);
      FillPixelPolygon(image_projector_.Project(quad), gray, &image);
    }
  }
  // Paint: the same polygons as the mask, without segmentation noise, to the image range.
  std::vector<Eigen::Vector2d> uv;
  const double s0 = context.s_cam - 2.0;
  for (const SimLaneLine& line : world_.lane_lines()) {
    auto it =
        std::lower_bound(line.pieces.begin(), line.pieces.end(), s0,
                         [](const SurfacePolygon& piece, double s) { return piece.s_max < s; });
    for (; it != line.pieces.end() && it->s_min <= far_s; ++it) {
      if (ToPixels(*it, context, image_projector_, &uv)) {
        FillPixelPolygon(uv, PaintGray(line.color), &image);
      }
    }
  }
  for (const SimMarking& m : world_.markings()) {
    if (!Overlaps(m.s_min, m.s_max, s0, far_s)) continue;
    for (const SurfacePolygon& component : m.components) {
      if (ToPixels(component, context, image_projector_, &uv)) {
        FillPixelPolygon(uv, PaintGray(m.color), &image);
      }
    }
  }
  FillOccluders(scenario_.occluders, road, context.T_cam_map, context.s_cam,
                context.index / scenario_.camera.rate_hz, image_projector_, kVehicleGray, 0,
                &image);
  // Fixed sensor texture (a repeating tile, so the image still compresses well).
  for (int r = 0; r < image.rows; ++r) {
    std::uint8_t* row = image.ptr<std::uint8_t>(r);
    const short* tile = texture_tile_.ptr<short>(r % texture_tile_.rows);
    for (int c = 0; c < image.cols; ++c) {
      row[c] = cv::saturate_cast<std::uint8_t>(row[c] + tile[c % texture_tile_.cols]);
    }
  }
  frame->image = image;
}

}  // namespace sim
}  // namespace ipm_road_mapper
