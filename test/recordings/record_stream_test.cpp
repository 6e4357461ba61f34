// recordings::RecordStream (rbsim/record_stream.hpp), the file-order stream rbsim check reads both files
// through: records in file order, buffers handed back and filled again, errors on damaged files
// worded as the other readers word them (mcap_tools::read_error), a consumer that stops early, and
// empty inputs.
#include "rbsim/record_stream.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "rbsim/recording.hpp"
#include "rbsim/subprocess.hpp"
#include "recordings_test_util.hpp"

namespace rbsim::test {
namespace {

namespace fs = std::filesystem;

// A payload of `size` bytes that names its message: `k` in its first bytes, then a pattern of k.
mcap::Bytes payload(std::uint32_t k, std::size_t size) {
  mcap::Bytes b(size < 4 ? 4 : size);
  std::memcpy(b.data(), &k, 4);
  for (std::size_t i = 4; i < b.size(); ++i) b[i] = static_cast<std::byte>((k * 31 + i) & 0xff);
  return b;
}

struct Planned {
  std::uint16_t channel;
  mcap::Timestamp log_time;
  std::size_t size = 16;
};

// A file of one schema, two channels (/a: 1, /b: 2) and `plan`'s messages in that order; message k
// carries payload(k, size) and sequence k.
void write_file(const fs::path& out, const std::vector<Planned>& plan,
                mcap::Compression compression = mcap::Compression::None, std::uint64_t chunk_size = 1 << 20) {
  mcap::Writer w;
  ASSERT_TRUE(w.open(out.string(), recordings::writer_options(compression, chunk_size)).ok());
  ASSERT_TRUE(w.add_schema({1, "test_msgs/msg/Blob", "ros2msg", bytes_of("uint8[] data\n")}).ok());
  ASSERT_TRUE(w.add_channel({1, 1, "/a", "cdr", {}}).ok());
  ASSERT_TRUE(w.add_channel({2, 1, "/b", "cdr", {}}).ok());
  for (std::uint32_t k = 0; k < plan.size(); ++k) {
    const Planned& p = plan[k];
    ASSERT_TRUE(w.write_message(p.channel, k, p.log_time, p.log_time, payload(k, p.size)).ok());
  }
  ASSERT_TRUE(w.close().ok());
}

// Everything `s` hands out, as "Schema 1", "Channel 2 /b", "Message 0 ch 1 t 30" (and checks each
// message's payload), until the end; recycling every message buffer.
std::vector<std::string> drain(recordings::RecordStream& s) {
  std::vector<std::string> seen;
  while (mcap::Record* r = s.next()) {
    if (auto* schema = std::get_if<mcap::Schema>(r)) {
      seen.push_back("Schema " + std::to_string(schema->id));
    } else if (auto* c = std::get_if<mcap::Channel>(r)) {
      seen.push_back("Channel " + std::to_string(c->id) + " " + c->topic);
    } else if (auto* m = std::get_if<mcap::Message>(r)) {
      EXPECT_EQ(m->data, payload(m->sequence, m->data.size())) << "message " << m->sequence;
      seen.push_back("Message " + std::to_string(m->sequence) + " ch " + std::to_string(m->channel_id) +
                     " t " + std::to_string(m->log_time));
      s.recycle(std::move(m->data));
    } else {
      seen.push_back("other");
    }
  }
  return seen;
}

TEST(RecordStream, ReadsMessagesInFileOrder) {
  TempDir dir;
  const fs::path file = dir / "order.mcap";
  // Log times out of order: the stream keeps the file's order (Recording sorts by log time).
  write_file(file, {{2, 30}, {1, 10}, {2, 20}, {1, 10}, {1, 5}});
  recordings::RecordStream s;
  ASSERT_TRUE(s.open(file.string()).ok());
  EXPECT_EQ(drain(s),
            (std::vector<std::string>{"Schema 1", "Channel 1 /a", "Channel 2 /b", "Message 0 ch 2 t 30",
                                      "Message 1 ch 1 t 10", "Message 2 ch 2 t 20", "Message 3 ch 1 t 10",
                                      "Message 4 ch 1 t 5"}));
  EXPECT_TRUE(s.status().ok()) << s.status().error().message;
  EXPECT_EQ(s.next(), nullptr) << "the end stays the end";
}

// Many chunks, compressed, more than the reader may run ahead (kPumpBytes), with every buffer
// given back: each message still arrives whole and in order (a refilled buffer holds its own
// message only).
TEST(RecordStream, ReadsManyChunksWithRecycledBuffersIntact) {
  TempDir dir;
  const fs::path file = dir / "many.mcap";
  std::vector<Planned> plan;
  for (std::uint32_t k = 0; k < 600; ++k)
    plan.push_back({static_cast<std::uint16_t>(1 + k % 2), 1000 + k, 100 + (k * 7919) % 9000});
  write_file(file, plan, mcap::Compression::Zstd, 32 << 10);
  recordings::RecordStream s;
  ASSERT_TRUE(s.open(file.string()).ok());
  const std::vector<std::string> seen = drain(s);
  ASSERT_EQ(seen.size(), 3 + plan.size());
  for (std::uint32_t k = 0; k < plan.size(); ++k) {
    EXPECT_EQ(seen[3 + k], "Message " + std::to_string(k) + " ch " + std::to_string(plan[k].channel) + " t " +
                               std::to_string(plan[k].log_time));
  }
  EXPECT_TRUE(s.status().ok()) << s.status().error().message;
}

// A file cut short: every complete record before the cut, then an error that names the file, says
// truncated and points at `rbsim log recover`, as Recording's and the log tools' errors do.
TEST(RecordStream, NamesATruncatedFileAndTheToolThatRecoversIt) {
  TempDir dir;
  const fs::path whole = dir / "whole.mcap";
  std::vector<Planned> plan;
  for (std::uint32_t k = 0; k < 200; ++k) plan.push_back({1, k, 2000});
  write_file(whole, plan, mcap::Compression::Zstd, 16 << 10);
  mcap::Bytes bytes = read_bytes(whole);
  bytes.resize(bytes.size() / 2);
  const fs::path cut = dir / "cut.mcap";
  write_bytes(cut, bytes);

  recordings::RecordStream s;
  ASSERT_TRUE(s.open(cut.string()).ok());
  const std::vector<std::string> seen = drain(s);
  EXPECT_GT(seen.size(), 3u) << "the complete chunks before the cut";
  EXPECT_LT(seen.size(), 3 + plan.size());
  const Status st = s.status();
  ASSERT_FALSE(st.ok());
  const std::string& m = st.error().message;
  EXPECT_EQ(m.rfind(cut.string() + ": truncated: ", 0), 0u) << m;
  EXPECT_NE(m.find("(rbsim log recover rebuilds a valid file from its complete chunks)"), std::string::npos)
      << m;
}

// A chunk whose bytes were changed: an error naming the file, saying corrupted and pointing at
// `rbsim log doctor`; the records before that chunk came through.
TEST(RecordStream, NamesACorruptedFileAndTheToolThatListsItsProblems) {
  TempDir dir;
  const fs::path file = dir / "damaged.mcap";
  std::vector<Planned> plan;
  for (std::uint32_t k = 0; k < 200; ++k) plan.push_back({2, k, 2000});
  write_file(file, plan, mcap::Compression::Zstd, 16 << 10);
  mcap::Bytes bytes = read_bytes(file);
  const RawRecord chunk = find_record(top_level_records(bytes), mcap::Opcode::Chunk, 2);
  ASSERT_GT(chunk.length, 200u);
  for (std::uint64_t i = chunk.offset + chunk.length - 100; i < chunk.offset + chunk.length - 50; ++i)
    bytes[i] ^= std::byte{0x5a};
  write_bytes(file, bytes);

  recordings::RecordStream s;
  ASSERT_TRUE(s.open(file.string()).ok());
  EXPECT_GT(drain(s).size(), 3u);
  const Status st = s.status();
  ASSERT_FALSE(st.ok());
  const std::string& m = st.error().message;
  EXPECT_EQ(m.rfind(file.string() + ": corrupted: ", 0), 0u) << m;
  EXPECT_NE(m.find("(rbsim log doctor lists the problems)"), std::string::npos) << m;
}

// What a stream of `path` ends with: open()'s error, or else status() once next() gave null.
Status stream_failure(const fs::path& path) {
  recordings::RecordStream s;
  if (Status st = s.open(path.string()); !st) return st;
  while (s.next() != nullptr) {
  }
  return s.status();
}

// Not a recording at all, and no file: an error naming the path, worded as Recording's.
TEST(RecordStream, NamesTheFileOfAnUnreadableInput) {
  TempDir dir;
  const fs::path junk = dir / "junk.mcap";
  write_bytes(junk, bytes_of("not mcap, not at all"));
  const Status st = stream_failure(junk);
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.error().message.rfind(junk.string() + ": ", 0), 0u) << st.error().message;
  auto recording = recordings::Recording::open(junk.string(), recordings::raw_options());
  ASSERT_FALSE(recording.ok());
  EXPECT_EQ(st.error().message, recording.error().message) << "one wording for both readers";

  const Status gone = stream_failure(dir / "missing.mcap");
  ASSERT_FALSE(gone.ok());
  EXPECT_NE(gone.error().message.find("missing.mcap"), std::string::npos) << gone.error().message;
}

// A file of zero bytes is no recording: an error naming it, worded as Recording's ("empty file
// (0 bytes): not an MCAP file", not a truncated file for log recover to save).
TEST(RecordStream, AnEmptyFileIsAnErrorNamingIt) {
  TempDir dir;
  const fs::path empty = dir / "empty.mcap";
  write_bytes(empty, {});
  const Status st = stream_failure(empty);
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.error().message.rfind(empty.string() + ": ", 0), 0u) << st.error().message;
  auto recording = recordings::Recording::open(empty.string(), recordings::raw_options());
  ASSERT_FALSE(recording.ok());
  EXPECT_EQ(st.error().message, recording.error().message) << "one wording for both readers";
}

// A finished recording that holds no message: its schema and channels, then the end, read whole.
TEST(RecordStream, ARecordingWithoutMessagesEndsAfterItsChannels) {
  TempDir dir;
  const fs::path file = dir / "none.mcap";
  write_file(file, {});
  recordings::RecordStream s;
  ASSERT_TRUE(s.open(file.string()).ok());
  EXPECT_EQ(drain(s), (std::vector<std::string>{"Schema 1", "Channel 1 /a", "Channel 2 /b"}));
  EXPECT_TRUE(s.status().ok()) << s.status().error().message;
}

// A consumer that stops after the first message of a file far larger than the reader may run
// ahead: stop() returns at once (the reader thread, waiting for room, sees it), and so does the
// destructor of a stream nobody read from.
TEST(RecordStream, StopsEarlyWithoutReadingTheRest) {
  TempDir dir;
  const fs::path file = dir / "large.mcap";
  std::vector<Planned> plan;
  for (std::uint32_t k = 0; k < 160; ++k) plan.push_back({1, k, 64 << 10});  // 10 MiB > kPumpBytes
  write_file(file, plan);
  const auto t0 = std::chrono::steady_clock::now();
  {
    recordings::RecordStream s;
    ASSERT_TRUE(s.open(file.string()).ok());
    int messages = 0;
    while (mcap::Record* r = s.next()) {
      if (std::get_if<mcap::Message>(r) != nullptr && ++messages == 1) break;
    }
    EXPECT_EQ(messages, 1);
    s.stop();
    s.stop();  // idempotent
  }
  {
    recordings::RecordStream unread;
    ASSERT_TRUE(unread.open(file.string()).ok());
  }  // the destructor stops the reader thread
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 10.0);
}

}  // namespace
}  // namespace rbsim::test
