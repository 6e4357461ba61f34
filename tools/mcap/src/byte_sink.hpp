// Byte sinks for the writer (the readers' byte sources are public: rbsim/mcap_records.hpp).
#pragma once

#include <cstdio>
#include <memory>

#include "rbsim/mcap.hpp"
#include "rbsim/mcap_records.hpp"

namespace rbsim::mcap::detail {

class ByteSink {
 public:
  virtual ~ByteSink() = default;
  virtual Status write(ByteView data) = 0;
  virtual Status flush() = 0;  // hand buffered bytes to the OS
  virtual Status close() = 0;
  virtual const Bytes& buffer() const = 0;  // memory sinks only; empty otherwise
  // Whether write_at() works: a regular file or memory (not a pipe or a device).
  virtual bool seekable() const = 0;
  // Overwrites bytes already written, at `offset` (< the bytes written so far); later write()s
  // still append.
  virtual Status write_at(std::uint64_t offset, ByteView data) = 0;
};

Result<std::unique_ptr<ByteSink>> open_file_sink(const std::string& path);
std::unique_ptr<ByteSink> make_buffer_sink();

inline Error out_of_range(std::uint64_t offset, std::uint64_t length, std::uint64_t size) {
  return Error{"read of " + std::to_string(length) + " bytes at offset " + std::to_string(offset) +
                   " past end of file (size " + std::to_string(size) + ")",
               ErrorCode::Truncated};
}

}  // namespace rbsim::mcap::detail
