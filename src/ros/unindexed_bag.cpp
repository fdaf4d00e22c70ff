#include "ipm_road_mapper/ros/unindexed_bag.h"

#include <bzlib.h>
#include <ros/serialization.h>
#include <rosbag/bag.h>
#include <roslz4/lz4s.h>
#include <topic_tools/shape_shifter.h>

#include <cstdint>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <vector>

#include "ipm_road_mapper/ros/bag_input.h"

namespace ipm_road_mapper {
namespace {

constexpr std::uint8_t kOpMessageData = 0x02;
constexpr std::uint8_t kOpChunk = 0x05;
constexpr std::uint8_t kOpConnection = 0x07;
constexpr std::uint32_t kMaxRecordBytes = 1u << 30;  // a larger length is a damaged record

std::uint32_t Le32(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
         (static_cast<std::uint32_t>(p[2]) << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
}

// A record's header fields (name -> raw value bytes).
using Fields = std::map<std::string, std::string>;

// Parses "len name=value" fields; nullopt when malformed.
std::optional<Fields> ParseFields(const std::uint8_t* p, std::size_t size) {
  Fields fields;
  std::size_t at = 0;
  while (at < size) {
    if (size - at < 4) return std::nullopt;
    const std::uint32_t len = Le32(p + at);
    at += 4;
    if (len > size - at) return std::nullopt;
    const std::string field(reinterpret_cast<const char*>(p + at), len);
    at += len;
    const std::size_t eq = field.find('=');
    if (eq == std::string::npos) return std::nullopt;
    fields[field.substr(0, eq)] = field.substr(eq + 1);
  }
  return fields;
}

// One record: header fields and data, within a byte buffer.
struct Record {
  Fields fields;
  const std::uint8_t* data = nullptr;
  std::uint32_t data_size = 0;
};

// Reads the record at buffer[*at]; false when the buffer ends inside it or it is malformed.
bool NextRecord(const std::vector<std::uint8_t>& buffer, std::size_t* at, Record* record) {
  const std::size_t size = buffer.size();
  if (size - *at < 4) return false;
  const std::uint32_t header_len = Le32(&buffer[*at]);
  if (header_len > kMaxRecordBytes || header_len > size - *at - 4) return false;
  auto fields = ParseFields(&buffer[*at + 4], header_len);
  if (!fields) return false;
  const std::size_t data_at = *at + 4 + header_len;
  if (size - data_at < 4) return false;
  const std::uint32_t data_len = Le32(&buffer[data_at]);
  if (data_len > kMaxRecordBytes || data_len > size - data_at - 4) return false;
  record->fields = std::move(*fields);
  record->data = &buffer[data_at + 4];
  record->data_size = data_len;
  *at = data_at + 4 + data_len;
  return true;
}

// Reads the next top-level record from the file into *buffer (header and data); false when
// the file ends inside it (or at its start) or it is malformed.
bool ReadRecord(std::istream& in, std::vector<std::uint8_t>* buffer, Record* record) {
  std::uint8_t len[4];
  if (!in.read(reinterpret_cast<char*>(len), 4)) return false;
  const std::uint32_t header_len = Le32(len);
  if (header_len > kMaxRecordBytes) return false;
  std::vector<std::uint8_t> header(header_len);
  if (!in.read(reinterpret_cast<char*>(header.data()), header_len)) return false;
  auto fields = ParseFields(header.data(), header.size());
  if (!fields || !in.read(reinterpret_cast<char*>(len), 4)) return false;
  const std::uint32_t data_len = Le32(len);
  if (data_len > kMaxRecordBytes) return false;
  buffer->resize(data_len);
  if (!in.read(reinterpret_cast<char*>(buffer->data()), data_len)) return false;
  record->fields = std::move(*fields);
  record->data = buffer->data();
  record->data_size = data_len;
  return true;
}

std::uint8_t Op(const Record& record) {
  const auto it = record.fields.find("op");
  return it == record.fields.end() || it->second.size() != 1
             ? 0
             : static_cast<std::uint8_t>(it->second[0]);
}

std::optional<std::uint32_t> U32Field(const Record& record, const char* name) {
  const auto it = record.fields.find(name);
  if (it == record.fields.end() || it->second.size() != 4) return std::nullopt;
  return Le32(reinterpret_cast<const std::uint8_t*>(it->second.data()));
}

// A chunk's records, decompressed; nullopt when they do not decompress.
std::optional<std::vector<std::uint8_t>> ChunkRecords(const Record& chunk) {
  const auto compression = chunk.fields.find("compression");
  const std::optional<std::uint32_t> size = U32Field(chunk, "size");
  if (compression == chunk.fields.end() || !size || *size > kMaxRecordBytes) return std::nullopt;
  std::vector<std::uint8_t> out(*size);
  if (compression->second == "none") {
    if (chunk.data_size != *size) return std::nullopt;
    std::memcpy(out.data(), chunk.data, *size);
    return out;
  }
  unsigned int out_size = *size;
  if (compression->second == "lz4") {
    const int rc = roslz4_buffToBuffDecompress(
        const_cast<char*>(reinterpret_cast<const char*>(chunk.data)), chunk.data_size,
        reinterpret_cast<char*>(out.data()), &out_size);
    if (rc != ROSLZ4_OK || out_size != *size) return std::nullopt;
    return out;
  }
  if (compression->second == "bz2") {
    const int rc = BZ2_bzBuffToBuffDecompress(
        reinterpret_cast<char*>(out.data()), &out_size,
        const_cast<char*>(reinterpret_cast<const char*>(chunk.data)), chunk.data_size, 0, 0);
    if (rc != BZ_OK || out_size != *size) return std::nullopt;
    return out;
  }
  return std::nullopt;
}

// A connection: its topic and the header fields a ShapeShifter needs.
struct Connection {
  std::string topic;
  Fields header;  // topic, type, md5sum, message_definition, [callerid, latching]
};

class Copier {
 public:
  explicit Copier(const std::string& copy_path) {
    out_.open(copy_path, rosbag::bagmode::Write);
    out_.setCompression(rosbag::compression::LZ4);
  }

  // The records of one chunk (connections, then messages).
  void CopyChunk(const std::vector<std::uint8_t>& records, BagSalvage* salvage) {
    std::size_t at = 0;
    Record record;
    while (NextRecord(records, &at, &record)) {
      const std::uint8_t op = Op(record);
      if (op == kOpConnection) {
        AddConnection(record);
      } else if (op == kOpMessageData) {
        CopyMessage(record, salvage);
      }
    }
  }

  void AddConnection(const Record& record) {
    const std::optional<std::uint32_t> id = U32Field(record, "conn");
    const auto topic = record.fields.find("topic");
    auto header = ParseFields(record.data, record.data_size);
    if (!id || topic == record.fields.end() || !header) return;
    connections_[*id] = {topic->second, std::move(*header)};
  }

  void CopyMessage(const Record& record, BagSalvage* salvage) {
    const std::optional<std::uint32_t> id = U32Field(record, "conn");
    const auto time = record.fields.find("time");
    if (!id || time == record.fields.end() || time->second.size() != 8) return;
    const auto connection = connections_.find(*id);
    if (connection == connections_.end()) return;  // its connection record was lost
    const auto* t = reinterpret_cast<const std::uint8_t*>(time->second.data());
    const ros::Time stamp(Le32(t), Le32(t + 4));
    const Fields& header = connection->second.header;
    auto field = [&](const char* name) {
      const auto it = header.find(name);
      return it == header.end() ? std::string() : it->second;
    };
    topic_tools::ShapeShifter message;
    message.morph(field("md5sum"), field("type"), field("message_definition"), field("latching"));
    ros::serialization::IStream stream(const_cast<std::uint8_t*>(record.data), record.data_size);
    message.read(stream);
    auto connection_header = boost::make_shared<ros::M_string>(header.begin(), header.end());
    out_.write(connection->second.topic, stamp, message, connection_header);
    if (salvage->messages == 0) salvage->first_stamp = stamp.toSec();
    salvage->last_stamp = stamp.toSec();
    ++salvage->messages;
  }

  void Close() { out_.close(); }

 private:
  rosbag::Bag out_;
  std::map<std::uint32_t, Connection> connections_;
};

}  // namespace

std::string SalvageUnindexedBag(const std::string& path, const std::string& copy_path,
                                BagSalvage* salvage) {
  *salvage = BagSalvage();
  std::ifstream in(path, std::ios::binary);
  if (!in) return "cannot open " + path;
  const std::string magic = "#ROSBAG V2.0\n";
  std::string head(magic.size(), '\0');
  if (!in.read(head.data(), static_cast<std::streamsize>(head.size())) || head != magic) {
    return "not a bag of format 2.0";
  }
  in.seekg(0, std::ios::end);
  const std::streamoff file_bytes = in.tellg();
  in.seekg(static_cast<std::streamoff>(magic.size()));
  try {
    Copier copier(copy_path);
    std::vector<std::uint8_t> buffer;
    Record record;
    salvage->end = "the last record is complete";
    while (in.peek() != std::char_traits<char>::eof()) {
      const std::streamoff record_at = in.tellg();
      if (!ReadRecord(in, &buffer, &record)) {
        salvage->end = "the file ends inside the record at byte " + std::to_string(record_at) +
                       " of " + std::to_string(file_bytes);
        break;
      }
      const std::uint8_t op = Op(record);
      if (op == kOpConnection) {
        copier.AddConnection(record);
      } else if (op == kOpChunk) {
        const std::optional<std::vector<std::uint8_t>> records = ChunkRecords(record);
        if (records) {
          ++salvage->chunks;
          copier.CopyChunk(*records, salvage);
        } else {
          ++salvage->bad_chunks;
        }
      }
    }
    copier.Close();
  } catch (const std::exception& e) {
    return std::string("cannot write the indexed copy ") + copy_path + ": " + e.what();
  }
  if (salvage->messages == 0) return "no message could be read in record order";
  return "";
}

OpenedBag::~OpenedBag() {
  bag_.close();
  std::error_code ignored;
  if (!copy_path_.empty()) std::filesystem::remove(copy_path_, ignored);
}

std::string OpenedBag::Open(const std::string& path, const std::string& copy_folder) {
  const std::string error = OpenBagForReading(path, &bag_);
  if (error.empty()) return "";
  const BagIndexCheck check = CheckBagIndex(path);
  if (!check.index_missing) return error;
  std::error_code ignored;
  std::filesystem::create_directories(copy_folder, ignored);
  copy_path_ = (std::filesystem::path(copy_folder) /
                ("." + std::filesystem::path(path).stem().string() + ".indexed.bag"))
                   .string();
  BagSalvage salvage;
  const std::string why = SalvageUnindexedBag(path, copy_path_, &salvage);
  if (!why.empty()) return error + " (reading it in record order failed too: " + why + ")";
  bag_.close();  // the failed open keeps the file
  if (const std::string reopen = OpenBagForReading(copy_path_, &bag_); !reopen.empty()) {
    return error + " (its indexed copy: " + reopen + ")";
  }
  salvage_ = salvage;
  index_problem_ = check.problem;
  return "";
}

}  // namespace ipm_road_mapper
