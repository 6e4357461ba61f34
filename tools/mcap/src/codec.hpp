// Chunk compression (spec registry: "lz4" is the LZ4 *frame* format, "zstd" a Zstandard frame).
#pragma once

#include <memory>

#include "rbsim/mcap.hpp"

namespace rbsim::mcap::detail {

class Compressor {
 public:
  Compressor(Compression compression, int level);
  ~Compressor();
  Compressor(const Compressor&) = delete;
  Compressor& operator=(const Compressor&) = delete;

  // Replaces `out` with the compressed form of `in`.
  Status compress(ByteView in, Bytes& out);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

Result<Compression> compression_from_name(std::string_view name);

}  // namespace rbsim::mcap::detail
