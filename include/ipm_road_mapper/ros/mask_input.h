// The mask subscription (ros/mask_transport), as a message_filters source of
// sensor_msgs/Image for the mask <-> camera_info synchronizer:
// - through image_transport when it has a plugin for the transport ("raw" always; others
//   such as "compressed" when their plugin package is installed), subscribing to
//   ros/mask_topic with that transport hint;
// - "compressed" without its image_transport plugin (Debian 12 ships none): a
//   sensor_msgs/CompressedImage subscriber on <mask_topic>/compressed, the topic that
//   transport publishes, decoded here (DecodeCompressedMask: lossless PNG only). A mask that
//   does not decode is handed on with the reason as its encoding, so the mapper counts it
//   as bad_mask_encoding.
#pragma once

#include <image_transport/image_transport.h>
#include <message_filters/simple_filter.h>
#include <ros/node_handle.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>

#include <memory>
#include <string>

namespace ipm_road_mapper {

class MaskInput : public message_filters::SimpleFilter<sensor_msgs::Image> {
 public:
  // Subscribes to `topic` with `transport` and `queue_size`. Throws std::invalid_argument
  // for a transport that neither image_transport nor the built-in decoder provides.
  MaskInput(ros::NodeHandle& nh, const std::string& topic, const std::string& transport,
            int queue_size);

  // How the masks are read, for the start-up log ("image_transport raw", ...).
  const std::string& description() const { return description_; }

  // Unsubscribes (idempotent).
  void Shutdown();

 private:
  void OnCompressed(const sensor_msgs::CompressedImageConstPtr& msg);

  std::unique_ptr<image_transport::ImageTransport> transport_;
  image_transport::Subscriber image_sub_;
  ros::Subscriber compressed_sub_;
  std::string description_;
};

}  // namespace ipm_road_mapper
