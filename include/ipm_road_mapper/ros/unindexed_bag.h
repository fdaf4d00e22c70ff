// Reading a bag that has no index (cut short, or its recording never closed), which
// rosbag's C++ API refuses to open: its records are read in file order (the bag format
// v2.0: chunk records holding connection and message records, lz4, bz2 or uncompressed),
// past the missing index, and every message that can be read is written into an indexed
// copy that rosbag then opens as usual. What `rosbag reindex` does, without modifying the
// original and without Python. Reading stops at the first record cut by the end of the
// file; a chunk that does not decompress is skipped and counted.
#pragma once

#include <rosbag/bag.h>

#include <cstddef>
#include <optional>
#include <string>

namespace ipm_road_mapper {

// What SalvageUnindexedBag read.
struct BagSalvage {
  std::size_t chunks = 0;      // chunks read
  std::size_t bad_chunks = 0;  // chunks that did not decompress (skipped)
  std::size_t messages = 0;    // messages written into the copy
  double first_stamp = 0.0;    // record times (s) of the first and last message copied
  double last_stamp = 0.0;
  std::string end;  // how reading ended, e.g. "the file ends inside a chunk"
};

// Reads the bag at `path` in record order and writes every readable message (record time,
// connection header kept) into a new lz4-compressed bag at `copy_path`. Empty on success
// (at least one message copied), otherwise one phrase why not.
std::string SalvageUnindexedBag(const std::string& path, const std::string& copy_path,
                                BagSalvage* salvage);

// A bag opened for reading: the file itself when rosbag can open it, else (its index
// missing) the indexed copy SalvageUnindexedBag makes in a folder, removed with this object.
class OpenedBag {
 public:
  OpenedBag() = default;
  OpenedBag(const OpenedBag&) = delete;
  OpenedBag& operator=(const OpenedBag&) = delete;
  // Closes the bag and removes the copy, if one was made.
  ~OpenedBag();

  // Opens `path`; without its index, salvages it into `<copy_folder>/.<stem>.indexed.bag`
  // (the folder is created) and opens that. Empty on success, else the one-line error of
  // OpenBagForReading (with why salvaging failed too, when it was tried).
  std::string Open(const std::string& path, const std::string& copy_folder);

  rosbag::Bag& bag() { return bag_; }
  // Set when the copy is what was opened.
  const std::optional<BagSalvage>& salvage() const { return salvage_; }
  // Why the bag had to be salvaged (CheckBagIndex's phrase); "" when not.
  const std::string& index_problem() const { return index_problem_; }

 private:
  rosbag::Bag bag_;
  std::string copy_path_;
  std::optional<BagSalvage> salvage_;
  std::string index_problem_;
};

}  // namespace ipm_road_mapper
