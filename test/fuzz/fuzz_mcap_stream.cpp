// libFuzzer target: the streaming MCAP reader over arbitrary bytes, every record reported
// (chunks, their contents, message indexes), CRCs verified. It must end (each record advances
// through a finite input) with a record or a status, never crash.
#include <cstddef>
#include <cstdint>
#include <span>

#include "rbsim/mcap.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace mcap = rbsim::mcap;
  const auto input = std::as_bytes(std::span(data, size));
  mcap::StreamOptions options;
  options.report_chunks = true;
  options.report_message_indexes = true;
  mcap::StreamReader reader;
  if (!reader.open_buffer(mcap::Bytes(input.begin(), input.end()), options).ok()) return 0;
  mcap::RecordEntry entry;
  std::uint64_t records = 0, last = 0;
  while (reader.next(entry)) {
    // Top-level positions only move forward: a reader that stands still would loop forever.
    if (!entry.chunk_offset && records > 0 && entry.offset < last) __builtin_trap();
    if (!entry.chunk_offset) last = entry.offset;
    ++records;
  }
  (void)reader.status();
  return 0;
}
