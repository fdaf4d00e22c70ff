#include "ipm_road_mapper/ros/segmentation/segmentation_msgs.h"

#include <cv_bridge/cv_bridge.h>
#include <sensor_msgs/image_encodings.h>

#include <opencv2/imgproc.hpp>

#include "ipm_road_mapper/ros/msg_conversion.h"

namespace ipm_road_mapper {

std::string CameraImageToBgr(const sensor_msgs::Image& msg, cv::Mat* image) {
  namespace enc = sensor_msgs::image_encodings;
  try {
    if (msg.encoding == enc::MONO8 || msg.encoding == enc::BGR8) {
      *image = cv_bridge::toCvCopy(msg)->image;
    } else if (msg.encoding == enc::MONO16) {
      *image = cv_bridge::toCvCopy(msg, enc::MONO8)->image;
    } else if (msg.encoding == enc::RGB8 || msg.encoding == enc::BGRA8 ||
               msg.encoding == enc::RGBA8) {
      *image = cv_bridge::toCvCopy(msg, enc::BGR8)->image;
    } else {
      return "image encoding '" + msg.encoding + "' is not mono8, mono16, bgr8 or rgb8";
    }
  } catch (const cv_bridge::Exception& e) {
    return std::string("image cannot be read: ") + e.what();
  }
  if (image->empty()) return "image is empty";
  return "";
}

sensor_msgs::Image SegmentedMaskMsg(const segmentation::SegmentedFrame& frame,
                                    const std_msgs::Header& header) {
  sensor_msgs::Image msg = MaskToImage(frame.mask);
  msg.header = header;
  return msg;
}

MaskInstances SegmentedInstancesMsg(const segmentation::SegmentedFrame& frame,
                                    const std_msgs::Header& header) {
  MaskInstances msg;
  msg.header = header;
  for (const segmentation::SegmentedInstance& instance : frame.instances) {
    msg.values.push_back(instance.value);
    msg.classes.push_back(segmentation::ToString(instance.paint_class));
    msg.confidences.push_back(static_cast<float>(instance.confidence));
    msg.pixels.push_back(static_cast<std::uint32_t>(instance.pixels));
  }
  return msg;
}

}  // namespace ipm_road_mapper
