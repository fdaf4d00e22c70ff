// The segmentation nodelet (ipm_road_mapper/SegmentMasksNodelet, docs/ros_api.md): camera
// images in, the mapper's 16UC1 instance masks out.
//   subscribes: image_raw + camera_info (image_transport CameraSubscriber)
//   publishes:  instances (sensor_msgs/Image 16UC1, the image's header),
//               instances/instances (MaskInstances: classes and confidences)
// The image callback only stores the newest frame in a one-frame slot and wakes the owned
// segmentation thread; a frame still waiting when a newer one arrives is dropped and counted
// (the frame-skip policy: when the network is slower than the camera the newest image is
// segmented, and each mask carries its own image's stamp, so the mapper interpolates the
// odometry there and maps fewer frames, never wrong ones). The extrinsic is looked up on tf
// for every frame (~base_frame -> ~extrinsic_frame, default the image's frame; set it to the
// mapper's refined camera frame to use the current calibration). Unload stops and joins the
// thread.
#pragma once

#include <image_transport/image_transport.h>
#include <nodelet/nodelet.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include <condition_variable>
#include <memory>
#include <mutex>
#include <thread>

#include "ipm_road_mapper/segmentation/openvino/frame_segmenter.h"

namespace ipm_road_mapper {

class SegmentMasksNodelet : public nodelet::Nodelet {
 public:
  ~SegmentMasksNodelet() override;

 private:
  void onInit() override;
  // Stores the frame in the slot (dropping the one waiting, counted); never blocks on the
  // network.
  void OnImage(const sensor_msgs::ImageConstPtr& image,
               const sensor_msgs::CameraInfoConstPtr& info);
  // The segmentation thread: waits for a frame, segments it, publishes.
  void Run();
  void SegmentAndPublish(const sensor_msgs::ImageConstPtr& image,
                         const sensor_msgs::CameraInfoConstPtr& info);
  void Stop();

  std::unique_ptr<segmentation::FrameSegmenter> segmenter_;
  std::string base_frame_, extrinsic_frame_;
  std::unique_ptr<tf2_ros::Buffer> tf_buffer_;
  std::unique_ptr<tf2_ros::TransformListener> tf_listener_;
  std::unique_ptr<image_transport::ImageTransport> transport_;
  image_transport::CameraSubscriber subscriber_;
  ros::Publisher mask_publisher_, instances_publisher_;

  std::mutex mutex_;
  std::condition_variable wake_;
  sensor_msgs::ImageConstPtr waiting_image_;
  sensor_msgs::CameraInfoConstPtr waiting_info_;
  bool stop_ = false;
  std::thread worker_;
  // Counted for the periodic log line.
  long received_ = 0, skipped_busy_ = 0, segmented_ = 0, failed_ = 0;
  double busy_ms_ = 0.0;
};

}  // namespace ipm_road_mapper
