// Chunk compression (spec registry: "lz4" is the LZ4 *frame* format, "zstd" a Zstandard frame).
#pragma once

#include <atomic>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <thread>

#include "rbsim/mcap.hpp"

namespace rbsim::mcap::detail {

class Compressor {
 public:
  Compressor(Compression compression, int level);
  ~Compressor();
  Compressor(const Compressor&) = delete;
  Compressor& operator=(const Compressor&) = delete;

  // Points `out` at the compressed form of `in` (for None: at `in`), valid until the next call.
  // The compressor's buffer is reused without being cleared first.
  Status compress(ByteView in, ByteView& out);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Compresses one chunk at a time on a thread of its own (WriterOptions::background_compression),
// so a recording's compression and chunk CRC run beside the work that produces its messages. One
// job at most: memory stays bounded by two chunks, and the writer writes results in submission
// order, so a file's bytes do not depend on the thread. Used by one (writer) thread.
class ChunkWorker {
 public:
  ChunkWorker(Compression compression, int level, bool crc);
  ~ChunkWorker();  // drops a job the thread has not started, lets a started one end, and joins
  ChunkWorker(const ChunkWorker&) = delete;
  ChunkWorker& operator=(const ChunkWorker&) = delete;

  // The job's uncompressed records: filled (or swapped in) while !pending(), then submit().
  Bytes& records() { return records_; }
  void submit();
  bool pending() const { return pending_; }
  // True once the submitted job has finished: wait() will not block.
  bool finished() const { return finished_.load(std::memory_order_acquire); }
  // Blocks until the job has finished; then payload() (compressed, or the records for None) and
  // crc() (CRC-32 of the records, 0 without CRCs) are the result until release().
  Status wait();
  ByteView payload() const;
  std::uint32_t crc() const { return crc_; }
  void release();  // clears records(); the next job may start

 private:
  void run();

  Compressor compressor_;
  const Compression compression_;
  const bool with_crc_;
  Bytes records_;
  ByteView compressed_;
  std::uint32_t crc_ = 0;
  Status status_;
  bool pending_ = false;  // writer thread only
  bool start_ = false;    // guarded by mutex_
  bool stop_ = false;     // guarded by mutex_
  std::atomic<bool> finished_{false};
  std::mutex mutex_;
  std::condition_variable cv_;
  std::thread thread_;  // last: started once everything above exists
};

Result<Compression> compression_from_name(std::string_view name);

// Decompresses chunks one after another (decompress_chunk's rules), keeping its zstd and lz4
// contexts between them: a fresh context per chunk is a fresh allocation, whose pages fault in
// again for every chunk of a file.
class Decompressor {
 public:
  Decompressor();
  ~Decompressor();
  Decompressor(const Decompressor&) = delete;
  Decompressor& operator=(const Decompressor&) = delete;

  // `records` are a Chunk's compressed records, `chunk` gives its compression, sizes and CRC
  // (its own records field is not read).
  Status decompress(const Chunk& chunk, ByteView records, Bytes& out, bool verify_crc);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rbsim::mcap::detail
