#include "ipm_road_mapper/ros/debug_image_publisher.h"

#include <cv_bridge/cv_bridge.h>
#include <ros/console.h>
#include <sensor_msgs/image_encodings.h>

#include <cmath>
#include <utility>

#include "ipm_road_mapper/pipeline/debug_overlay.h"
#include "ipm_road_mapper/ros/msg_conversion.h"

namespace ipm_road_mapper {
namespace {

constexpr std::size_t kImageRing = 10;
constexpr double kNoImageAfterS = 2.0;  // then overlays are drawn over the mask

bool SameStamp(const ros::Time& a, double b) { return std::abs(ToSeconds(a) - b) < 1e-6; }

// The camera image as BGR or gray; an empty Mat when it cannot be converted.
cv::Mat ImageToCv(const sensor_msgs::ImageConstPtr& image) {
  if (!image) return cv::Mat();
  namespace enc = sensor_msgs::image_encodings;
  try {
    if (image->encoding == enc::MONO8) return cv_bridge::toCvCopy(image, enc::MONO8)->image;
    return cv_bridge::toCvCopy(image, enc::BGR8)->image;
  } catch (const std::exception& e) {
    ROS_WARN_THROTTLE(10.0, "debug_image: cannot convert the camera image (%s): %s",
                      image->encoding.c_str(), e.what());
    return cv::Mat();
  }
}

}  // namespace

DebugImagePublisher::DebugImagePublisher(
    ros::NodeHandle& nh, ros::NodeHandle& private_nh, std::string image_topic,
    MapperOptions options, ClassTable classes,
    std::function<void(const sensor_msgs::ImageConstPtr&)> enqueue)
    : nh_(nh),
      image_topic_(std::move(image_topic)),
      options_(std::move(options)),
      classes_(std::move(classes)),
      enqueue_(std::move(enqueue)) {
  const ros::SubscriberStatusCallback on_connection =
      [this](const ros::SingleSubscriberPublisher&) { OnConnection(); };
  std::lock_guard<std::mutex> lock(mutex_);
  pub_ = private_nh.advertise<sensor_msgs::Image>("debug_image", 1, on_connection, on_connection);
}

DebugImagePublisher::~DebugImagePublisher() { Shutdown(); }

void DebugImagePublisher::Shutdown() {
  ros::Subscriber old;
  ros::Publisher pub;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    shut_down_ = true;
    old = std::move(image_sub_);
    image_sub_ = ros::Subscriber();
    pub = pub_;
    pending_.reset();
    images_.clear();
  }
  // Outside the lock: shutdown() waits for a running image callback.
  old.shutdown();
  pub.shutdown();
}

bool DebugImagePublisher::active() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return !shut_down_ && pub_ && pub_.getNumSubscribers() > 0;
}

void DebugImagePublisher::OnConnection() {
  ros::Subscriber old;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (shut_down_) return;
    const bool wanted = pub_.getNumSubscribers() > 0;
    if (wanted && !image_sub_ && !image_topic_.empty()) {
      image_sub_ = nh_.subscribe<sensor_msgs::Image>(
          image_topic_, 5, [this](const sensor_msgs::ImageConstPtr& image) { enqueue_(image); });
      last_image_wall_ = ros::WallTime::now();  // give the image topic time to start
    } else if (!wanted && image_sub_) {
      old = std::move(image_sub_);
      image_sub_ = ros::Subscriber();
      images_.clear();
      pending_.reset();
    }
  }
  old.shutdown();
}

void DebugImagePublisher::AddFrame(const FrameInput& frame, const Eigen::Isometry3d& T_map_base,
                                   const Eigen::Isometry3d& T_base_cam,
                                   std::shared_ptr<const VectorMap> map) {
  if (!active() || !map) return;
  PendingFrame job{frame, T_map_base, T_base_cam, std::move(map)};
  sensor_msgs::ImageConstPtr image;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& candidate : images_) {
      if (SameStamp(candidate->header.stamp, frame.stamp)) image = candidate;
    }
    const bool images_flow = (ros::WallTime::now() - last_image_wall_).toSec() < kNoImageAfterS;
    if (!image && images_flow) {
      pending_ = std::move(job);  // its image may still come
      return;
    }
  }
  Draw(job, image);
}

void DebugImagePublisher::AddImage(const sensor_msgs::ImageConstPtr& image) {
  std::optional<PendingFrame> job;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (shut_down_) return;
    last_image_wall_ = ros::WallTime::now();
    images_.push_back(image);
    while (images_.size() > kImageRing) images_.pop_front();
    if (pending_ && SameStamp(image->header.stamp, pending_->frame.stamp)) {
      job = std::move(pending_);
      pending_.reset();
    }
  }
  if (job) Draw(*job, image);
}

void DebugImagePublisher::Draw(const PendingFrame& job, const sensor_msgs::ImageConstPtr& image) {
  ros::Publisher pub;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (shut_down_) return;
    pub = pub_;
  }
  OverlayFrame frame;
  frame.image = ImageToCv(image);
  frame.mask = job.frame.mask;
  frame.camera = job.frame.camera;
  frame.T_base_cam = job.T_base_cam;
  frame.T_map_base = job.T_map_base;
  const FrameObservations measured =
      MeasureFrame(job.frame.mask, job.frame.camera, job.T_base_cam, classes_, options_);
  const cv::Mat overlay = DrawDebugOverlay(frame, measured, *job.map);
  std_msgs::Header header;
  header.stamp = FromSeconds(job.frame.stamp);
  header.frame_id = image ? image->header.frame_id : "";
  pub.publish(cv_bridge::CvImage(header, sensor_msgs::image_encodings::BGR8, overlay).toImageMsg());
}

}  // namespace ipm_road_mapper
