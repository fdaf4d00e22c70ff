// Damaging a bag written by a test: bytes flipped inside one LZ4 chunk's compressed data, the
// chunk header and the index left intact (what test/tools/damage_bag.py does for the tool test).
#pragma once

#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <string>

namespace ipm_road_mapper {
namespace test {

// Flips 32 bytes inside the compressed data of the `chunk`-th (0-based, in file order) LZ4
// chunk of the bag at `path`; the chunk's data must be longer than 232 bytes.
inline void CorruptChunk(const std::string& path, int chunk) {
  std::fstream file(path, std::ios::in | std::ios::out | std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  std::size_t at = 0;
  for (int k = 0; k <= chunk; ++k) {
    at = bytes.find("compression=lz4", k == 0 ? 0 : at + 1);
    ASSERT_NE(at, std::string::npos) << "the bag has fewer than " << chunk + 1 << " chunks";
  }
  file.clear();
  for (std::size_t i = at + 200; i < at + 232; ++i) {
    file.seekp(static_cast<std::streamoff>(i));
    file.put(static_cast<char>(~bytes[i]));
  }
  ASSERT_TRUE(file.good());
}

}  // namespace test
}  // namespace ipm_road_mapper
