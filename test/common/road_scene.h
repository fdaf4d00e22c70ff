// A small road scene for the Mapper's tests: a 1280x720 camera 1.5 m high looking down 5
// deg, a class table with a dashed lane and an arrow, and masks rendered from ground
// polygons (an arrow at x in [20, 23] m, a dashed lane at y = 1.8 m) as the vehicle drives
// along x.
#pragma once

#include <opencv2/imgproc.hpp>
#include <optional>
#include <vector>

#include "common/test_scene.h"
#include "ipm_road_mapper/core/frontend/instance_extraction.h"
#include "ipm_road_mapper/core/geometry/ipm.h"
#include "ipm_road_mapper/core/mapper/mapper.h"

namespace ipm_road_mapper {
namespace test {

// The scene's camera (test_scene.h): 1280x720, f = 1000 px, centered.
inline CameraIntrinsics TestCamera() { return Intrinsics1280x720(); }

// Camera 1.5 m high, 1.5 m ahead of base_link, pitched down 5 degrees.
inline Eigen::Isometry3d TestExtrinsic() { return MountedCamera(0.0, 5.0 * M_PI / 180.0, 0.0); }

inline ClassTable TestClasses() {
  return ClassTable::Load(OptionsReader(YAML::Load(R"(
classes:
  - {id: 2, name: lane_white_dashed, kind: lane, style: dashed}
  - {id: 10, name: arrow_straight, kind: marking}
)"),
                                        ""));
}

// Fills the ground polygon (map frame, z = 0) seen from T_map_base into the mask.
inline void FillGround(const std::vector<Eigen::Vector3d>& polygon_map,
                       const Eigen::Isometry3d& T_map_base, int value, cv::Mat* mask) {
  const Ipm ipm(PinholeCamera(TestCamera()), TestExtrinsic(), 100.0);
  std::vector<cv::Point> pixels;
  for (std::size_t i = 0; i < polygon_map.size(); ++i) {
    const Eigen::Vector3d a = polygon_map[i], b = polygon_map[(i + 1) % polygon_map.size()];
    for (int k = 0; k < 20; ++k) {
      Eigen::Vector2d uv;
      const Eigen::Vector3d p_base = T_map_base.inverse() * (a + (b - a) * (k / 20.0));
      if (!ipm.BaseToPixel(p_base, &uv)) return;
      pixels.emplace_back(static_cast<int>(std::lround(uv.x())),
                          static_cast<int>(std::lround(uv.y())));
    }
  }
  cv::fillPoly(*mask, std::vector<std::vector<cv::Point>>{pixels}, cv::Scalar(value));
}

inline std::vector<Eigen::Vector3d> Rect(double x0, double x1, double y0, double y1) {
  return {{x0, y0, 0}, {x1, y0, 0}, {x1, y1, 0}, {x0, y1, 0}};
}

inline Eigen::Isometry3d PoseAt(double x) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation().x() = x;
  return T;
}

// A frame with an arrow at x in [20, 23] m, y in [-0.3, 0.3] m, and a dashed lane at
// y = 1.8 m (3 m dashes, 6 m period), seen from base_link at x_vehicle.
inline FrameInput RoadFrame(double stamp, double x_vehicle, bool with_arrow = true) {
  FrameInput in;
  in.stamp = stamp;
  in.camera = TestCamera();
  in.T_map_base_odom = PoseAt(x_vehicle);
  in.mask = cv::Mat::zeros(720, 1280, CV_16UC1);
  for (double x = 0.0; x < 120.0; x += 6.0) {
    if (x < x_vehicle + 4.0 || x > x_vehicle + 35.0) continue;
    FillGround(Rect(x, x + 3.0, 1.725, 1.875), in.T_map_base_odom, 2001, &in.mask);
  }
  if (with_arrow && x_vehicle + 6.0 < 20.0) {
    FillGround(Rect(20.0, 23.0, -0.3, 0.3), in.T_map_base_odom, 10001, &in.mask);
  }
  return in;
}

// What the Mapper's rooms share, for tests that drive a room alone: the options with the
// effective gates, the scene's classes, a store and counters, and the front end's first step.
struct RoomRig {
  explicit RoomRig(MapperOptions o) : options(std::move(o)) {
    options.association = EffectiveAssociationOptions(options);
  }
  // The frame's observations, extracted with T_base_cam (the IPM is written to *ipm).
  FrameObservations Observe(const FrameInput& in, const Eigen::Isometry3d& T_base_cam,
                            std::optional<Ipm>* ipm) const {
    ipm->emplace(PinholeCamera(in.camera), T_base_cam, options.ipm.max_range_m);
    return ExtractObservations(in.mask, classes, **ipm, options.ipm.error_model,
                               options.extraction);
  }
  MapperOptions options;
  ClassTable classes = TestClasses();
  MapStore store{4.0};
  MapperCounters counters;
};

}  // namespace test
}  // namespace ipm_road_mapper
