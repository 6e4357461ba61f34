// Small pieces shared by the log tools (info, doctor, recover, export).
#pragma once

#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <string_view>

#include "rbsim/mcap.hpp"
#include "rbsim/mcap_records.hpp"

namespace rbsim::mcap_tools::detail {

// Opcode and content length in front of every record.
inline constexpr std::size_t kPrefix = mcap::RecordReader::kPrefixSize;

// Bounded random access to a file: every read is checked against the size found at open.
class FileBytes {
 public:
  // Empty message on success.
  std::string open(const std::string& path);
  std::uint64_t size() const { return size_; }
  // Reads [offset, offset + length) into `out`; false when the range is outside the file or the
  // read fails.
  bool read(std::uint64_t offset, std::uint64_t length, mcap::Bytes& out);

 private:
  struct Closer {
    void operator()(std::FILE* f) const { std::fclose(f); }
  };
  std::unique_ptr<std::FILE, Closer> file_;
  std::uint64_t size_ = 0;
};

inline std::uint64_t le64(const std::uint8_t* p) {
  std::uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}

// "Chunk", "Message", ... for an opcode; "opcode 0x42" for unknown ones.
std::string opcode_name(std::uint8_t opcode);

}  // namespace rbsim::mcap_tools::detail
