// The synthetic drive: a scenario and a seed in, per-frame instance masks, gray images,
// true and odometry poses, odometry samples at their own rate, and the ground truth out.
// Deterministic: the same scenario and seed give bit-identical output.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "ipm_road_mapper/core/frontend/class_table.h"
#include "ipm_road_mapper/core/geometry/pinhole_camera.h"
#include "ipm_road_mapper/core/io/ground_truth.h"
#include "ipm_road_mapper/sim/renderer.h"
#include "ipm_road_mapper/sim/scenario.h"
#include "ipm_road_mapper/sim/vehicle.h"
#include "ipm_road_mapper/sim/world.h"

namespace ipm_road_mapper {
namespace sim {

// One instance of a rendered mask and where it came from.
struct RenderedInstance {
  enum class Source { kLane, kMarking, kSpurious };
  int value = 0;  // class_id * 1000 + instance index
  Source source = Source::kMarking;
  int gt_id = 0;  // SimLaneLine::id or SimMarking::id; 0 for spurious blobs
  int pixels = 0;
};

// One camera frame of the drive.
struct SimFrame {
  int index = 0;
  std::int64_t stamp_ns = 0;
  double stamp = 0.0;  // seconds
  cv::Mat mask;        // CV_16UC1 instance mask
  cv::Mat image;       // CV_8UC1 gray rendering; empty when not rendered for this frame
  Eigen::Isometry3d T_map_base_true = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d T_map_base_odom = Eigen::Isometry3d::Identity();  // interpolated odometry
  std::vector<RenderedInstance> instances;                            // those present in the mask
};

// One odometry message: the noisy pose and the body-frame velocities of the noisy track.
struct OdometrySample {
  std::int64_t stamp_ns = 0;
  double stamp = 0.0;
  Eigen::Isometry3d T_map_base = Eigen::Isometry3d::Identity();
  Eigen::Vector3d linear_velocity_base = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity_base = Eigen::Vector3d::Zero();
};

// What RenderFrame draws.
struct RenderSettings {
  bool segmentation_noise = true;  // off: exact masks (range limit and min size still apply)
  bool image = true;               // also render the gray image
  bool record_visibility = true;   // count the frame in the ground truth's visible_frames
};

// Generates a drive. Construction computes the trajectory and odometry; frames are
// rendered on demand (in any order).
class DriveSimulator {
 public:
  // `max_frames` > 0 caps the number of frames (short test drives).
  DriveSimulator(const ScenarioOptions& scenario, const ClassTable& classes, std::uint32_t seed,
                 int max_frames = 0);

  int num_frames() const { return static_cast<int>(frames_.size()); }
  const ScenarioOptions& scenario() const { return scenario_; }
  const SimWorld& world() const { return world_; }
  const PinholeCamera& camera() const { return camera_; }
  const Eigen::Isometry3d& T_base_cam_true() const { return T_base_cam_true_; }
  const Eigen::Isometry3d& T_base_cam_rough() const { return T_base_cam_rough_; }
  const std::vector<OdometrySample>& odometry() const { return odometry_; }
  std::int64_t FrameStampNs(int k) const;
  // True and odometry pose of frame k.
  const GroundTruthFrame& frame(int k) const { return frames_[k]; }
  // Whether /camera/image_raw is published for frame k (camera.image_every_n_frames).
  bool ImageDue(int k) const;

  // Line-of-sight test of frame k's camera over the road relief (what the renderer uses).
  SightProfile CameraSight(int k) const { return MakeContext(k).sight; }

  // Renders frame k.
  SimFrame RenderFrame(int k, const RenderSettings& settings = {});

  // The ground truth: markings (with the visible_frames recorded so far), lane lines over
  // the stretch the camera can see, frames, camera and extrinsics.
  GroundTruth ground_truth() const;

 private:
  // Per-frame geometry shared by the mask and image renderers.
  struct FrameContext {
    int index = 0;
    Eigen::Isometry3d T_cam_map = Eigen::Isometry3d::Identity();
    double s_cam = 0.0;  // the camera's arc length along the road
    SightProfile sight;
  };
  FrameContext MakeContext(int k) const;
  // Pixel polygon of a surface polygon; false when hidden by the road or outside the frustum.
  static bool ToPixels(const SurfacePolygon& polygon, const FrameContext& context,
                       const FrustumProjector& projector, std::vector<Eigen::Vector2d>* uv);
  void ComputeOdometry();
  void RenderMask(const FrameContext& context, bool noise, SimFrame* frame);
  void RenderImage(const FrameContext& context, SimFrame* frame) const;

  ScenarioOptions scenario_;
  std::uint32_t seed_;
  SimWorld world_;
  PinholeCamera camera_;
  Eigen::Isometry3d T_base_cam_true_, T_base_cam_rough_;
  VehicleTrajectory trajectory_;
  FrustumProjector mask_projector_, image_projector_;
  cv::Mat texture_tile_;  // CV_16SC1 sensor-texture tile added to the gray image
  std::vector<GroundTruthFrame> frames_;
  std::vector<std::int64_t> frame_stamps_ns_;
  std::vector<OdometrySample> odometry_;
  std::vector<int> marking_class_ids_;  // for spurious blobs
  std::vector<int> visible_frames_;     // per marking
  double lane_s0_ = 0.0, lane_s1_ = 0.0;
};

}  // namespace sim
}  // namespace ipm_road_mapper
