// libFuzzer target: the indexed MCAP reader (footer -> summary -> chunk indexes) over arbitrary
// bytes: every query a tool makes (all messages, a topic filter, a time range, attachments,
// metadata, the data-section CRC) returns a value or an error, never crashes.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "rbsim/mcap.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace mcap = rbsim::mcap;
  const auto input = std::as_bytes(std::span(data, size));
  mcap::IndexedReader reader;
  if (!reader.open_buffer(mcap::Bytes(input.begin(), input.end())).ok()) return 0;
  (void)reader.read_all_messages();
  mcap::ReadMessagesOptions filtered;
  for (const auto& [id, channel] : reader.channels()) {
    filtered.topics.push_back(channel.topic);
    break;
  }
  filtered.start_time = 1;
  filtered.end_time = 1'000'000'000'000ULL;
  std::uint64_t seen = 0;
  (void)reader.read_messages(filtered, [&](const mcap::MessageEntry& m) {
    (void)m.message.data.size();
    return ++seen < 100000;
  });
  for (const mcap::AttachmentIndex& a : reader.attachment_indexes()) (void)reader.read_attachment(a);
  for (const mcap::MetadataIndex& m : reader.metadata_indexes()) (void)reader.read_metadata(m);
  (void)reader.verify_data_section_crc();
  return 0;
}
