#include "ipm_road_mapper/ros/bag_input.h"

#include <console_bridge/console.h>
#include <rosbag/exceptions.h>
#include <rosbag/view.h>
#include <sensor_msgs/Image.h>
#include <tf2/buffer_core.h>
#include <tf2/exceptions.h>
#include <tf2_msgs/TFMessage.h>

#include <filesystem>
#include <fstream>

#include "ipm_road_mapper/ros/msg_conversion.h"

namespace ipm_road_mapper {
namespace {

constexpr const char* kTfStaticTopic = "/tf_static";
constexpr char kBagVersionLine[] = "#ROSBAG V2.0\n";
constexpr std::uint32_t kMaxFileHeaderBytes = 4096;  // rosbag pads the record to 4096 bytes

// A little-endian unsigned integer of `bytes` bytes at `data`.
std::uint64_t LittleEndian(const char* data, std::size_t bytes) {
  std::uint64_t value = 0;
  for (std::size_t i = bytes; i-- > 0;) {
    value = (value << 8) | static_cast<unsigned char>(data[i]);
  }
  return value;
}

// The fields (name -> raw value) of a bag record header: each is a 4-byte length, then
// "name=value". False when the lengths do not add up.
bool ParseRecordHeader(const std::string& header, std::map<std::string, std::string>* fields) {
  std::size_t at = 0;
  while (at + 4 <= header.size()) {
    const std::uint64_t length = LittleEndian(&header[at], 4);
    at += 4;
    if (length > header.size() - at) return false;
    const std::string field = header.substr(at, length);
    at += length;
    const std::size_t equals = field.find('=');
    if (equals == std::string::npos) return false;
    (*fields)[field.substr(0, equals)] = field.substr(equals + 1);
  }
  return at == header.size();
}

// Silences console_bridge (which cpp_common's header parser logs to) while it lives: a
// damaged index must end in map_from_bag's one error line only.
class QuietConsoleBridge {
 public:
  QuietConsoleBridge() : level_(console_bridge::getLogLevel()) {
    console_bridge::setLogLevel(console_bridge::CONSOLE_BRIDGE_LOG_NONE);
  }
  ~QuietConsoleBridge() { console_bridge::setLogLevel(level_); }
  QuietConsoleBridge(const QuietConsoleBridge&) = delete;
  QuietConsoleBridge& operator=(const QuietConsoleBridge&) = delete;

 private:
  console_bridge::LogLevel level_;
};

}  // namespace

BagIndexCheck CheckBagIndex(const std::string& path) {
  BagIndexCheck check;
  std::ifstream in(path, std::ios::binary);
  const std::string version_line = kBagVersionLine;
  std::string start(version_line.size() + 4, '\0');
  if (!in.read(&start[0], start.size()) || start.compare(0, version_line.size(), version_line)) {
    check.problem = "not a ROS bag of version 2.0";
    return check;
  }
  const std::uint64_t header_bytes = LittleEndian(&start[version_line.size()], 4);
  std::string header(header_bytes <= kMaxFileHeaderBytes ? header_bytes : 0, '\0');
  std::map<std::string, std::string> fields;
  if (header.empty() || !in.read(&header[0], header.size()) ||
      !ParseRecordHeader(header, &fields) || fields["op"] != std::string(1, '\x03') ||
      fields["index_pos"].size() != 8) {
    check.problem = "its file header is damaged";
    return check;
  }
  check.is_bag_v2 = true;
  const std::uint64_t index_pos = LittleEndian(fields["index_pos"].data(), 8);
  std::error_code error;
  const std::uintmax_t file_bytes = std::filesystem::file_size(path, error);
  if (index_pos == 0) {
    check.index_missing = true;
    check.problem = "it has no index (its recording was not closed)";
  } else if (!error && index_pos >= file_bytes) {
    check.index_missing = true;
    check.problem = "it is truncated (its index would start at byte " + std::to_string(index_pos) +
                    " of a " + std::to_string(file_bytes) + "-byte file)";
  }
  return check;
}

std::string OpenBagForReading(const std::string& path, rosbag::Bag* bag) {
  try {
    const QuietConsoleBridge quiet;
    bag->open(path, rosbag::bagmode::Read);
    return "";
  } catch (const rosbag::BagException& e) {
    const BagIndexCheck check = CheckBagIndex(path);
    const std::string reindex = "run `rosbag reindex " + path +
                                "` (it keeps the original as *.orig.bag) and map the "
                                "reindexed bag";
    if (check.index_missing) {
      return path + ": cannot read bag: " + check.problem +
             ", and rosbag's C++ API reads only indexed bags; " + reindex;
    }
    if (check.is_bag_v2) {
      return path + ": cannot read bag: " + e.what() + " (its index may be damaged: " + reindex +
             ")";
    }
    return path + ": cannot read bag: " + e.what() + " (" + check.problem + ")";
  }
}

std::string FirstReadableMaskFrame(rosbag::Bag* bag, const std::string& mask_topic) {
  for (std::size_t unreadable = 0;; ++unreadable) {
    rosbag::View masks(*bag, rosbag::TopicQuery(mask_topic));
    if (masks.size() <= unreadable) return "";
    auto message = masks.begin();
    for (std::size_t k = 0; k < unreadable; ++k) ++message;
    try {
      const auto mask = message->instantiate<sensor_msgs::Image>();
      return mask ? mask->header.frame_id : "";
    } catch (const rosbag::BagException&) {
      const std::string path = bag->getFileName();
      bag->close();
      bag->open(path, rosbag::bagmode::Read);
    } catch (const std::exception&) {
      return "";  // not an Image: no camera frame (the extrinsic error says so)
    }
  }
}

std::map<std::string, std::string> BagTopicTypes(const rosbag::Bag& bag) {
  std::map<std::string, std::string> types;
  rosbag::View view(bag);
  for (const rosbag::ConnectionInfo* connection : view.getConnections()) {
    types[connection->topic] = connection->datatype;
  }
  return types;
}

std::string CheckBagTopics(const rosbag::Bag& bag,
                           const std::vector<std::pair<std::string, std::string>>& required) {
  const std::map<std::string, std::string> types = BagTopicTypes(bag);
  for (const auto& [topic, type] : required) {
    const auto found = types.find(topic);
    if (found == types.end()) {
      std::string list;
      for (const auto& entry : types) list += (list.empty() ? "" : ", ") + entry.first;
      return "topic " + topic + " (" + type +
             ") is not in the bag (bag topics: " + (list.empty() ? "none" : list) + ")";
    }
    if (found->second != type) {
      return "topic " + topic + " has type " + found->second + ", expected " + type;
    }
  }
  return "";
}

std::string LookupStaticTransform(const rosbag::Bag& bag, const std::string& parent_frame,
                                  const std::string& child_frame, Eigen::Isometry3d* T) {
  tf2::BufferCore buffer;
  std::size_t transforms = 0;
  rosbag::View view(bag, rosbag::TopicQuery(kTfStaticTopic));
  for (const rosbag::MessageInstance& message : view) {
    tf2_msgs::TFMessage::ConstPtr tf;
    try {
      tf = message.instantiate<tf2_msgs::TFMessage>();
    } catch (const std::exception& e) {  // a corrupt chunk
      return std::string(kTfStaticTopic) + " cannot be read (" + e.what() + ")";
    }
    if (!tf) return std::string(kTfStaticTopic) + " is not tf2_msgs/TFMessage";
    for (const geometry_msgs::TransformStamped& transform : tf->transforms) {
      // setTransform rejects (and logs) malformed transforms itself.
      if (buffer.setTransform(transform, "bag", /*is_static=*/true)) ++transforms;
    }
  }
  if (transforms == 0) return std::string("the bag has no ") + kTfStaticTopic + " transforms";
  geometry_msgs::TransformStamped T_parent_child;
  try {
    T_parent_child = buffer.lookupTransform(parent_frame, child_frame, ros::Time(0));
  } catch (const tf2::TransformException& e) {
    return std::string(kTfStaticTopic) + " has no transform " + parent_frame + " -> " +
           child_frame + " (" + e.what() + ")";
  }
  const std::string error = TransformToIsometry(T_parent_child.transform, T);
  return error.empty() ? "" : std::string(kTfStaticTopic) + ": " + error;
}

}  // namespace ipm_road_mapper
