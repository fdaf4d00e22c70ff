// generate_drive: renders a synthetic drive (docs/synthetic_drives.md) into a bag plus its
// ground truth.
//
//   rosrun ipm_road_mapper generate_drive --scenario <yaml> --seed <n>
//                         --out <dir> [--classes <yaml>] [--max-frames <n>]
//
// Writes <dir>/drive.bag (/camera/camera_info, /camera/instances, /camera/image_raw, /odom,
// /tf_static), <dir>/ground_truth.json, <dir>/trajectory_true_tum.txt and
// <dir>/trajectory_odom_tum.txt, and prints a summary. --help lists the options (exit 0).
// Bad input (command line included): one error line, exit 2.
#include <nav_msgs/Odometry.h>
#include <ros/package.h>
#include <rosbag/bag.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <tf2_msgs/TFMessage.h>

#include <boost/make_shared.hpp>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>

#include "ipm_road_mapper/core/io/ground_truth.h"
#include "ipm_road_mapper/core/map/vector_map.h"
#include "ipm_road_mapper/pipeline/command_line.h"
#include "ipm_road_mapper/sim/drive_simulator.h"
#include "ipm_road_mapper/sim/ipm_check.h"

namespace irm = ipm_road_mapper;
namespace fs = std::filesystem;

namespace {

// An input error (the command line is checked by CommandLine): one line, exit code 2.
struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct Arguments {
  std::string scenario, out, classes;
  std::uint32_t seed = 0;
  int max_frames = 0;
};

// Parses the command line (pipeline/command_line.h): the exit code when the tool stops
// there (--help: 0, a bad command line: 2), else nullopt with *a filled in.
std::optional<int> ParseArguments(int argc, char** argv, Arguments* a) {
  std::int64_t seed = 0, max_frames = 0;
  irm::CommandLine line("generate_drive",
                        "Renders a synthetic drive (docs/synthetic_drives.md) into <out>/drive.bag "
                        "plus its ground truth and TUM trajectories.");
  line.Required("scenario", "<yaml>", &a->scenario, "scenario file (config/scenarios/*.yaml)")
      .Integer("seed", "<n>", &seed, 0, 4294967295LL, true, "", "random seed (noise, odometry)")
      .Required("out", "<dir>", &a->out, "output folder (created if needed)")
      .Optional("classes", "<yaml>", &a->classes,
                "classes.yaml beside the scenario's folder, else the package's "
                "config/classes.yaml",
                "class table")
      .Integer("max-frames", "<n>", &max_frames, 1, 1000000, false, "every frame of the scenario",
               "render at most this many frames");
  if (const std::optional<int> exit_code = line.ParseOrExitCode(argc, argv)) return exit_code;
  a->seed = static_cast<std::uint32_t>(seed);
  a->max_frames = static_cast<int>(max_frames);
  return std::nullopt;
}

// The class table when --classes is not given: beside the scenario folder
// (config/scenarios/..), else the installed package's config/.
std::string DefaultClassesFile(const std::string& scenario) {
  const fs::path beside = fs::path(scenario).parent_path().parent_path() / "classes.yaml";
  return fs::exists(beside) ? beside.string()
                            : ros::package::getPath("ipm_road_mapper") + "/config/classes.yaml";
}

ros::Time ToRosTime(std::int64_t stamp_ns) {
  ros::Time t;
  t.fromNSec(static_cast<std::uint64_t>(stamp_ns));
  return t;
}

void FillPose(const Eigen::Isometry3d& T, geometry_msgs::Pose* pose) {
  const Eigen::Quaterniond q(T.linear());
  pose->position.x = T.translation().x();
  pose->position.y = T.translation().y();
  pose->position.z = T.translation().z();
  pose->orientation.x = q.x();
  pose->orientation.y = q.y();
  pose->orientation.z = q.z();
  pose->orientation.w = q.w();
}

sensor_msgs::CameraInfo MakeCameraInfo(const irm::CameraIntrinsics& in) {
  sensor_msgs::CameraInfo info;
  info.width = in.width;
  info.height = in.height;
  info.distortion_model = "plumb_bob";
  info.D.assign(in.distortion.begin(), in.distortion.end());
  info.K = {in.fx, 0.0, in.cx, 0.0, in.fy, in.cy, 0.0, 0.0, 1.0};
  info.R = {1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0};
  info.P = {in.fx, 0.0, in.cx, 0.0, 0.0, in.fy, in.cy, 0.0, 0.0, 0.0, 1.0, 0.0};
  return info;
}

// sensor_msgs/Image from a continuous cv::Mat (host byte order is little-endian here).
sensor_msgs::Image MakeImage(const cv::Mat& mat, const std::string& encoding,
                             const std_msgs::Header& header) {
  sensor_msgs::Image image;
  image.header = header;
  image.height = mat.rows;
  image.width = mat.cols;
  image.encoding = encoding;
  image.is_bigendian = 0;
  image.step = static_cast<std::uint32_t>(mat.cols * mat.elemSize());
  image.data.resize(static_cast<std::size_t>(image.step) * mat.rows);
  for (int r = 0; r < mat.rows; ++r)
    std::memcpy(&image.data[r * image.step], mat.ptr(r), image.step);
  return image;
}

nav_msgs::Odometry MakeOdometry(const irm::sim::OdometrySample& sample,
                                const irm::sim::OdometryOptions& options) {
  nav_msgs::Odometry odom;
  odom.header.stamp = ToRosTime(sample.stamp_ns);
  odom.header.frame_id = "odom";
  odom.child_frame_id = "base_link";
  FillPose(sample.T_map_base, &odom.pose.pose);
  const double xy_var = std::pow(options.xy_std_m, 2) + std::pow(options.jitter_xy_m, 2);
  const double yaw_var = std::pow((options.yaw_std_deg + options.jitter_yaw_deg) * M_PI / 180.0, 2);
  const double small = 1e-4;
  for (int i = 0; i < 6; ++i) odom.pose.covariance[i * 7] = small;
  odom.pose.covariance[0] = odom.pose.covariance[7] = std::max(xy_var, 1e-6);
  odom.pose.covariance[35] = std::max(yaw_var, 1e-8);
  for (int i = 0; i < 3; ++i) {
    (&odom.twist.twist.linear.x)[i] = sample.linear_velocity_base(i);
    (&odom.twist.twist.angular.x)[i] = sample.angular_velocity_base(i);
  }
  for (int i = 0; i < 6; ++i) odom.twist.covariance[i * 7] = small;
  return odom;
}

// /tf_static with the rough extrinsic, written with a latching connection header.
void WriteTfStatic(rosbag::Bag* bag, const Eigen::Isometry3d& T_base_cam,
                   const std::string& camera_frame, std::int64_t stamp_ns) {
  tf2_msgs::TFMessage message;
  geometry_msgs::TransformStamped tf;
  tf.header.stamp = ToRosTime(stamp_ns);
  tf.header.frame_id = "base_link";
  tf.child_frame_id = camera_frame;
  const Eigen::Quaterniond q(T_base_cam.linear());
  tf.transform.translation.x = T_base_cam.translation().x();
  tf.transform.translation.y = T_base_cam.translation().y();
  tf.transform.translation.z = T_base_cam.translation().z();
  tf.transform.rotation.x = q.x();
  tf.transform.rotation.y = q.y();
  tf.transform.rotation.z = q.z();
  tf.transform.rotation.w = q.w();
  message.transforms.push_back(tf);
  auto header = boost::make_shared<ros::M_string>();
  (*header)["type"] = ros::message_traits::datatype<tf2_msgs::TFMessage>();
  (*header)["md5sum"] = ros::message_traits::md5sum<tf2_msgs::TFMessage>();
  (*header)["message_definition"] = ros::message_traits::definition<tf2_msgs::TFMessage>();
  (*header)["callerid"] = "/generate_drive";
  (*header)["latching"] = "1";
  bag->write("/tf_static", tf.header.stamp, message, header);
}

// Renders every frame into the bag, interleaving odometry in stamp order. Returns the number
// of images written.
std::size_t WriteBag(irm::sim::DriveSimulator* drive, const std::string& bag_path) {
  const irm::sim::ScenarioOptions& scenario = drive->scenario();
  rosbag::Bag bag(bag_path, rosbag::bagmode::Write);
  bag.setCompression(rosbag::compression::LZ4);
  const auto& odometry = drive->odometry();
  const std::string camera_frame = scenario.camera.frame_id;
  WriteTfStatic(&bag, drive->T_base_cam_rough(), camera_frame,
                std::min(odometry.front().stamp_ns, drive->FrameStampNs(0)));
  const sensor_msgs::CameraInfo info_template = MakeCameraInfo(scenario.camera.intrinsics);
  std::size_t next_odometry = 0, images = 0;
  auto write_odometry_until = [&](std::int64_t stamp_ns) {
    for (; next_odometry < odometry.size() && odometry[next_odometry].stamp_ns <= stamp_ns;
         ++next_odometry) {
      const auto& sample = odometry[next_odometry];
      bag.write("/odom", ToRosTime(sample.stamp_ns), MakeOdometry(sample, scenario.odometry));
    }
  };
  for (int k = 0; k < drive->num_frames(); ++k) {
    irm::sim::RenderSettings settings;
    settings.image = drive->ImageDue(k);
    const irm::sim::SimFrame frame = drive->RenderFrame(k, settings);
    write_odometry_until(frame.stamp_ns);
    std_msgs::Header header;
    header.seq = k;
    header.stamp = ToRosTime(frame.stamp_ns);
    header.frame_id = camera_frame;
    sensor_msgs::CameraInfo info = info_template;
    info.header = header;
    bag.write("/camera/camera_info", header.stamp, info);
    bag.write("/camera/instances", header.stamp, MakeImage(frame.mask, "16UC1", header));
    if (!frame.image.empty()) {
      bag.write("/camera/image_raw", header.stamp, MakeImage(frame.image, "mono8", header));
      ++images;
    }
  }
  write_odometry_until(odometry.back().stamp_ns);
  bag.close();
  return images;
}

// ground_truth.json and the two TUM trajectories (at the camera stamps).
void WriteGroundTruth(const irm::GroundTruth& gt, const fs::path& out) {
  irm::SaveGroundTruthJson(gt, (out / "ground_truth.json").string());
  std::vector<irm::StampedPose> true_poses, odom_poses;
  for (const auto& f : gt.frames) {
    true_poses.push_back({f.stamp, f.T_map_base_true});
    odom_poses.push_back({f.stamp, f.T_map_base_odom});
  }
  irm::WriteTumTrajectory(true_poses, (out / "trajectory_true_tum.txt").string());
  irm::WriteTumTrajectory(odom_poses, (out / "trajectory_odom_tum.txt").string());
}

int Run(const Arguments& args) {
  const auto start = std::chrono::steady_clock::now();
  const irm::ClassTable classes = irm::ClassTable::LoadFile(args.classes);
  const irm::sim::ScenarioOptions scenario = irm::sim::LoadScenarioFile(args.scenario, classes);
  irm::sim::DriveSimulator drive(scenario, classes, args.seed, args.max_frames);
  fs::create_directories(args.out);
  const std::string bag_path = (fs::path(args.out) / "drive.bag").string();
  const std::size_t images = WriteBag(&drive, bag_path);
  const irm::GroundTruth gt = drive.ground_truth();
  WriteGroundTruth(gt, args.out);

  const irm::sim::PlainIpmError ipm =
      irm::sim::ComputePlainIpmError(gt, scenario.ipm_check.max_distance_m);
  int seen = 0;
  for (const auto& m : gt.markings) seen += m.visible_frames > 0;
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("generate_drive: scenario '%s', seed %u -> %s\n", scenario.name.c_str(), args.seed,
              args.out.c_str());
  std::printf("  frames: %d at %.1f Hz (%.1f s), images: %zu, odometry: %zu at %.1f Hz\n",
              drive.num_frames(), scenario.camera.rate_hz,
              (drive.num_frames() - 1) / scenario.camera.rate_hz, images, drive.odometry().size(),
              scenario.odometry.rate_hz);
  std::printf("  markings: %zu (%d seen in a mask), lane lines: %zu\n", gt.markings.size(), seen,
              gt.lanes.size());
  std::printf(
      "  plain IPM marking error: %.3f +- %.3f m (xy %.3f +- %.3f m, max %.3f m) over %d "
      "markings, %d observations within %.0f m\n",
      ipm.mean_m, ipm.std_m, ipm.mean_xy_m, ipm.std_xy_m, ipm.max_m, ipm.markings, ipm.observations,
      scenario.ipm_check.max_distance_m);
  std::printf("  bag: %s, %.1f MB; took %.1f s\n", bag_path.c_str(), fs::file_size(bag_path) / 1e6,
              seconds);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Arguments args;
  if (const std::optional<int> exit_code = ParseArguments(argc, argv, &args)) return *exit_code;
  try {
    if (args.classes.empty()) args.classes = DefaultClassesFile(args.scenario);
    if (!fs::is_regular_file(args.scenario)) {
      throw InputError(args.scenario + ": no such scenario file");
    }
    return Run(args);
  } catch (const InputError& e) {
    std::cerr << "generate_drive: error: " << e.what() << std::endl;
  } catch (const irm::OptionsError& e) {
    std::cerr << "generate_drive: error: " << e.what() << std::endl;
  } catch (const std::exception& e) {
    std::cerr << "generate_drive: error: " << e.what() << std::endl;
    return 1;
  }
  return 2;
}
