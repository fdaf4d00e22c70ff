// Offline segmentation: copies a bag and adds the instance masks the mapper reads.
//
//   rosrun ipm_road_mapper segment_bag --bag IN.bag --out OUT.bag [--model DIR]
//        [--config mapper.yaml] [--segmentation-config segmentation.yaml] [--debug-dir DIR]
//
// Every message of IN.bag is copied to OUT.bag. For each image on the config's
// ros.image_topic (/camera/image_raw) with a camera_info of the same stamp on
// ros.camera_info_topic, the network (default: Open Model Zoo road-segmentation-adas-0001,
// ../shared/models/ from the package when present) gives the paint, the ground-plane
// instancer splits and classifies it with the rough extrinsic (input.extrinsic, else the
// bag's /tf_static base_frame -> the image's frame), and the 16UC1 mask is written on
// ros.mask_topic (/camera/instances) with the image's header, its instances and confidences
// on <mask_topic>/instances (MaskInstances). Masks already on those topics are replaced.
// --debug-dir writes an overlay PNG per frame. Prints the counts and the rate on one core.
// Exit status: 0 done (or --help); 2 bad input, one line on stderr; 1 the output failed.
#include <ros/package.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>
#include <vector>

#include "ipm_road_mapper/pipeline/command_line.h"
#include "ipm_road_mapper/pipeline/extrinsic_source.h"
#include "ipm_road_mapper/pipeline/mapper_config.h"
#include "ipm_road_mapper/ros/bag_input.h"
#include "ipm_road_mapper/ros/msg_conversion.h"
#include "ipm_road_mapper/ros/segmentation/segmentation_msgs.h"
#include "ipm_road_mapper/ros/segmentation/segmentation_overlay.h"
#include "ipm_road_mapper/segmentation/openvino/frame_segmenter.h"

namespace ipm_road_mapper {
namespace {

namespace fs = std::filesystem;

struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct Arguments {
  std::string bag, out, model, config, segmentation_config, debug_dir;
};

std::string PackageFile(const std::string& relative) {
  try {
    return FindPackageFile(ros::package::getPath("ipm_road_mapper"), relative);
  } catch (const OptionsError& e) {
    throw InputError(e.what());
  }
}

// The default model: ../shared/models/road-segmentation-adas-0001 beside the package.
std::string DefaultModel() {
  const fs::path package = fs::path(PackageFile("config/segmentation.yaml")).parent_path() / "..";
  const fs::path model = package / ".." / "shared" / "models" / "road-segmentation-adas-0001";
  std::error_code error;
  if (!fs::is_directory(model, error)) {
    throw InputError("no --model given and no " + model.lexically_normal().string() +
                     "; get road-segmentation-adas-0001 from Open Model Zoo "
                     "(docs/segmentation.md)");
  }
  return model.lexically_normal().string();
}

// Camera infos by stamp (a bag's are few and small).
std::map<ros::Time, sensor_msgs::CameraInfo> ReadCameraInfos(const rosbag::Bag& bag,
                                                             const std::string& topic) {
  std::map<ros::Time, sensor_msgs::CameraInfo> infos;
  for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery(topic))) {
    const sensor_msgs::CameraInfo::ConstPtr info = m.instantiate<sensor_msgs::CameraInfo>();
    if (info) infos[info->header.stamp] = *info;
  }
  return infos;
}

double Median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

// What the run did, printed at the end.
struct Tally {
  long images = 0, segmented = 0, no_camera_info = 0, unreadable = 0, replaced = 0;
  segmentation::InstanceCounters counters;
  std::vector<double> inference_ms, instances_ms;
};

void PrintSummary(const Tally& t, const std::string& model_file) {
  using segmentation::PaintClass;
  const segmentation::InstanceCounters& c = t.counters;
  std::printf("segment_bag: model %s\n", model_file.c_str());
  std::printf(
      "images: %ld, segmented %ld, skipped: no camera_info %ld, unreadable %ld; "
      "old masks replaced %ld\n",
      t.images, t.segmented, t.no_camera_info, t.unreadable, t.replaced);
  std::printf("instances:");
  for (int k = 0; k < segmentation::kPaintClassCount; ++k) {
    std::printf(" %s %ld", segmentation::ToString(static_cast<PaintClass>(k)), c.instances[k]);
  }
  std::printf(
      "\ndropped: speckle %ld, blobs %d, short lines %d, wide strokes %d, "
      "low confidence %d (pieces %ld)\n",
      c.speckle, c.dropped.blobs, c.dropped.short_lines, c.dropped.wide_strokes,
      c.dropped.low_confidence, c.pieces);
  const double inference = Median(t.inference_ms), instances = Median(t.instances_ms);
  std::printf("rate on one core: %.1f frames/s (median %.1f ms network + %.1f ms instances)\n",
              inference + instances > 0.0 ? 1000.0 / (inference + instances) : 0.0, inference,
              instances);
}

// Segments one image message into *out (mask + instances at the image's bag time).
void SegmentImage(const rosbag::MessageInstance& m, const sensor_msgs::Image& image_msg,
                  const std::map<ros::Time, sensor_msgs::CameraInfo>& infos,
                  const Eigen::Isometry3d& T_base_cam, const std::string& mask_topic,
                  const Arguments& args, segmentation::FrameSegmenter* segmenter, rosbag::Bag* out,
                  Tally* tally) {
  const auto info = infos.find(image_msg.header.stamp);
  if (info == infos.end()) {
    ++tally->no_camera_info;
    return;
  }
  CameraIntrinsics intrinsics;
  cv::Mat image;
  if (!CameraInfoToIntrinsics(info->second, &intrinsics).empty() ||
      !CameraImageToBgr(image_msg, &image).empty() || image.cols != intrinsics.width ||
      image.rows != intrinsics.height) {
    ++tally->unreadable;
    return;
  }
  const segmentation::FrameSegmenter::Result result =
      segmenter->Segment(image, PinholeCamera(intrinsics), T_base_cam);
  out->write(mask_topic, m.getTime(), SegmentedMaskMsg(result.frame, image_msg.header));
  out->write(mask_topic + "/instances", m.getTime(),
             SegmentedInstancesMsg(result.frame, image_msg.header));
  ++tally->segmented;
  tally->counters.Add(result.frame.counters);
  tally->inference_ms.push_back(result.inference_ms);
  tally->instances_ms.push_back(result.instances_ms);
  if (!args.debug_dir.empty()) {
    char name[64];
    std::snprintf(name, sizeof(name), "/%06ld.png", tally->images - 1);
    cv::imwrite(args.debug_dir + name,
                SegmentationOverlay(image, result.paint_probability > 0.5, result.frame));
  }
}

int Run(const Arguments& args) {
  const MapperConfig config = LoadMapperConfigFile(args.config);
  const std::string model_path = args.model.empty() ? DefaultModel() : args.model;
  const segmentation::SegmentationConfig seg_config = segmentation::LoadSegmentationConfig(
      args.segmentation_config, fs::is_directory(model_path) ? model_path : "");
  // One core: the network's threads (model.threads) and OpenCV's.
  cv::setNumThreads(seg_config.model.threads == 1 ? 1 : -1);
  rosbag::Bag in;
  const std::string open_error = OpenBagForReading(args.bag, &in);
  if (!open_error.empty()) throw InputError(open_error);
  const RosOptions& ros = config.ros;
  const std::string topics_error = CheckBagTopics(
      in,
      {{ros.image_topic, "sensor_msgs/Image"}, {ros.camera_info_topic, "sensor_msgs/CameraInfo"}});
  if (!topics_error.empty()) throw InputError(topics_error);
  const TransformLookup lookup = [&in](const std::string& parent, const std::string& child,
                                       Eigen::Isometry3d* T) {
    return LookupStaticTransform(in, parent, child, T);
  };
  ExtrinsicChoice extrinsic;
  const std::string extrinsic_error =
      ChooseExtrinsic(config.mapper.input, FirstReadableMaskFrame(&in, ros.image_topic), lookup,
                      "/tf_static", &extrinsic);
  if (!extrinsic_error.empty()) throw InputError(extrinsic_error);
  segmentation::FrameSegmenter segmenter(model_path, seg_config);
  if (!args.debug_dir.empty()) {
    fs::create_directories(args.debug_dir);
    segmenter.instancer().KeepGroundView(true);
  }
  const std::map<ros::Time, sensor_msgs::CameraInfo> infos =
      ReadCameraInfos(in, ros.camera_info_topic);
  std::printf("segment_bag: extrinsic from %s\n", extrinsic.source.c_str());

  rosbag::Bag out;
  out.open(args.out, rosbag::bagmode::Write);
  Tally tally;
  for (const rosbag::MessageInstance& m : rosbag::View(in)) {
    if (m.getTopic() == ros.mask_topic || m.getTopic() == ros.mask_topic + "/instances") {
      ++tally.replaced;
      continue;
    }
    out.write(m.getTopic(), m.getTime(), m, m.getConnectionHeader());
    if (m.getTopic() != ros.image_topic) continue;
    const sensor_msgs::Image::ConstPtr image = m.instantiate<sensor_msgs::Image>();
    if (!image) continue;
    ++tally.images;
    SegmentImage(m, *image, infos, extrinsic.T_base_cam, ros.mask_topic, args, &segmenter, &out,
                 &tally);
  }
  out.close();
  PrintSummary(tally, segmenter.model().model_file());
  return 0;
}

}  // namespace
}  // namespace ipm_road_mapper

int main(int argc, char** argv) {
  using namespace ipm_road_mapper;
  Arguments args;
  CommandLine line("segment_bag",
                   "Copies a bag and adds the instance masks of its camera images "
                   "(docs/segmentation.md).");
  line.Required("bag", "<in.bag>", &args.bag, "the bag with the camera's images and camera_info")
      .Required("out", "<out.bag>", &args.out, "the copy with the masks added")
      .Optional("model", "<dir or file>", &args.model,
                "../shared/models/road-segmentation-adas-0001 beside the package",
                "the network: an OpenVINO IR (.xml) or ONNX file, or a folder holding one "
                "(and its paint_model.yaml)")
      .Optional("config", "<mapper.yaml>", &args.config, "config/mapper.yaml of the package",
                "the topics (ros:) and the extrinsic (input:)")
      .Optional("segmentation-config", "<segmentation.yaml>", &args.segmentation_config,
                "config/segmentation.yaml of the package",
                "the network's class table and the "
                "instancer's rules")
      .Optional("debug-dir", "<dir>", &args.debug_dir, "none", "an overlay PNG per frame");
  if (const std::optional<int> code = line.ParseOrExitCode(argc, argv)) return *code;
  try {
    if (args.config.empty()) args.config = PackageFile("config/mapper.yaml");
    if (args.segmentation_config.empty()) {
      args.segmentation_config = PackageFile("config/segmentation.yaml");
    }
    return Run(args);
  } catch (const InputError& e) {
    std::cerr << "segment_bag: error: " << e.what() << "\n";
    return 2;
  } catch (const OptionsError& e) {
    std::cerr << "segment_bag: error: " << e.what() << "\n";
    return 2;
  } catch (const rosbag::BagException& e) {
    std::cerr << "segment_bag: error: " << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "segment_bag: error: " << e.what() << "\n";
    return 2;
  }
}
