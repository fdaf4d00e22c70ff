#include "ipm_road_mapper/ros/segmentation/segment_masks_nodelet.h"

#include <ros/package.h>
#include <tf2_eigen/tf2_eigen.h>

#include <filesystem>
#include <pluginlib/class_list_macros.hpp>

#include "ipm_road_mapper/MaskInstances.h"
#include "ipm_road_mapper/pipeline/mapper_config.h"
#include "ipm_road_mapper/ros/msg_conversion.h"
#include "ipm_road_mapper/ros/segmentation/segmentation_msgs.h"

namespace ipm_road_mapper {
namespace {

// The default model: ../shared/models/road-segmentation-adas-0001 beside the package.
std::string DefaultModelPath(const std::string& package_path) {
  namespace fs = std::filesystem;
  return (fs::path(package_path) / ".." / "shared" / "models" / "road-segmentation-adas-0001")
      .lexically_normal()
      .string();
}

}  // namespace

SegmentMasksNodelet::~SegmentMasksNodelet() { Stop(); }

void SegmentMasksNodelet::Stop() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (worker_.joinable()) worker_.join();
}

void SegmentMasksNodelet::onInit() {
  ros::NodeHandle& nh = getNodeHandle();
  ros::NodeHandle& private_nh = getPrivateNodeHandle();
  const std::string package = ros::package::getPath("ipm_road_mapper");
  std::string model, config;
  private_nh.param<std::string>("model", model, DefaultModelPath(package));
  private_nh.param<std::string>("segmentation_config", config,
                                FindPackageFile(package, "config/segmentation.yaml"));
  private_nh.param<std::string>("base_frame", base_frame_, "base_link");
  private_nh.param<std::string>("extrinsic_frame", extrinsic_frame_, "");
  try {
    const segmentation::SegmentationConfig loaded = segmentation::LoadSegmentationConfig(
        config, std::filesystem::is_directory(model) ? model : "");
    segmenter_ = std::make_unique<segmentation::FrameSegmenter>(model, loaded);
  } catch (const std::exception& e) {
    // A missing model or a bad config: say so once and stay idle (nothing is published).
    NODELET_ERROR("segment_masks: %s (model '%s', config '%s'); not segmenting", e.what(),
                  model.c_str(), config.c_str());
    return;
  }
  NODELET_INFO("segment_masks: model %s", segmenter_->model().model_file().c_str());
  tf_buffer_ = std::make_unique<tf2_ros::Buffer>();
  tf_listener_ = std::make_unique<tf2_ros::TransformListener>(*tf_buffer_);
  mask_publisher_ = nh.advertise<sensor_msgs::Image>("instances", 5);
  instances_publisher_ = nh.advertise<MaskInstances>("instances/instances", 5);
  worker_ = std::thread([this] { Run(); });
  transport_ = std::make_unique<image_transport::ImageTransport>(nh);
  subscriber_ = transport_->subscribeCamera("image_raw", 2, &SegmentMasksNodelet::OnImage, this);
}

void SegmentMasksNodelet::OnImage(const sensor_msgs::ImageConstPtr& image,
                                  const sensor_msgs::CameraInfoConstPtr& info) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++received_;
    if (waiting_image_) ++skipped_busy_;
    waiting_image_ = image;
    waiting_info_ = info;
  }
  wake_.notify_one();
}

void SegmentMasksNodelet::Run() {
  for (;;) {
    sensor_msgs::ImageConstPtr image;
    sensor_msgs::CameraInfoConstPtr info;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [this] { return stop_ || waiting_image_; });
      if (stop_) return;
      image.swap(waiting_image_);
      info.swap(waiting_info_);
    }
    SegmentAndPublish(image, info);
  }
}

void SegmentMasksNodelet::SegmentAndPublish(const sensor_msgs::ImageConstPtr& image,
                                            const sensor_msgs::CameraInfoConstPtr& info) {
  CameraIntrinsics intrinsics;
  cv::Mat bgr;
  std::string error = CameraInfoToIntrinsics(*info, &intrinsics);
  if (error.empty()) error = CameraImageToBgr(*image, &bgr);
  if (error.empty() && (bgr.cols != intrinsics.width || bgr.rows != intrinsics.height)) {
    error = "image size differs from camera_info's";
  }
  Eigen::Isometry3d T_base_cam = Eigen::Isometry3d::Identity();
  if (error.empty()) {
    const std::string camera = extrinsic_frame_.empty() ? image->header.frame_id : extrinsic_frame_;
    try {
      T_base_cam = tf2::transformToEigen(
          tf_buffer_->lookupTransform(base_frame_, camera, ros::Time(0)).transform);
    } catch (const tf2::TransformException& e) {
      error = std::string("no extrinsic: ") + e.what();
    }
  }
  if (!error.empty()) {
    ++failed_;
    NODELET_WARN_THROTTLE(5.0, "segment_masks: frame skipped: %s", error.c_str());
    return;
  }
  const segmentation::FrameSegmenter::Result result =
      segmenter_->Segment(bgr, PinholeCamera(intrinsics), T_base_cam);
  mask_publisher_.publish(SegmentedMaskMsg(result.frame, image->header));
  instances_publisher_.publish(SegmentedInstancesMsg(result.frame, image->header));
  ++segmented_;
  busy_ms_ += result.inference_ms + result.instances_ms;
  long received = 0, skipped = 0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    received = received_;
    skipped = skipped_busy_;
  }
  NODELET_INFO_THROTTLE(10.0,
                        "segment_masks: %ld images, %ld segmented (%.1f ms each), %ld skipped "
                        "while busy (the newest is segmented), %ld failed",
                        received, segmented_, busy_ms_ / segmented_, skipped, failed_);
}

}  // namespace ipm_road_mapper

PLUGINLIB_EXPORT_CLASS(ipm_road_mapper::SegmentMasksNodelet, nodelet::Nodelet)
