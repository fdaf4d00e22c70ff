#include "ipm_road_mapper/ros/mask_input.h"

#include <algorithm>
#include <stdexcept>
#include <vector>

#include "ipm_road_mapper/ros/compressed_mask.h"

namespace ipm_road_mapper {
namespace {

// The image_transport plugin names that can be loaded ("raw", "compressed", ...).
bool ImageTransportHas(image_transport::ImageTransport& it, const std::string& transport) {
  const std::vector<std::string> loadable = it.getLoadableTransports();
  return std::find(loadable.begin(), loadable.end(), transport) != loadable.end() ||
         std::find(loadable.begin(), loadable.end(), "image_transport/" + transport) !=
             loadable.end();
}

}  // namespace

MaskInput::MaskInput(ros::NodeHandle& nh, const std::string& topic, const std::string& transport,
                     int queue_size)
    : transport_(std::make_unique<image_transport::ImageTransport>(nh)) {
  const auto on_image = [this](const sensor_msgs::ImageConstPtr& image) { signalMessage(image); };
  if (transport == "raw" || ImageTransportHas(*transport_, transport)) {
    image_sub_ = transport_->subscribe(topic, static_cast<std::uint32_t>(queue_size), on_image,
                                       ros::VoidPtr(), image_transport::TransportHints(transport));
    description_ = "image_transport " + transport + " (" + image_sub_.getTopic() + ")";
  } else if (transport == "compressed") {
    compressed_sub_ = nh.subscribe(topic + "/compressed", static_cast<std::uint32_t>(queue_size),
                                   &MaskInput::OnCompressed, this);
    description_ = "compressed png, decoded by the nodelet (" + compressed_sub_.getTopic() + ")";
  } else {
    throw std::invalid_argument("ros.mask_transport '" + transport +
                                "': no image_transport plugin of that name is installed "
                                "(raw and compressed always work)");
  }
}

void MaskInput::Shutdown() {
  image_sub_.shutdown();
  compressed_sub_.shutdown();
}

void MaskInput::OnCompressed(const sensor_msgs::CompressedImageConstPtr& msg) {
  auto image = boost::make_shared<sensor_msgs::Image>();
  const std::string error = DecodeCompressedMask(*msg, image.get());
  if (!error.empty()) {
    image->header = msg->header;
    image->encoding = error;  // counted as bad_mask_encoding, with the reason
  }
  signalMessage(sensor_msgs::ImageConstPtr(image));
}

}  // namespace ipm_road_mapper
