// A recording streamed in file order on a reader thread of its own: for a consumer that takes
// records as the file holds them (rbsim check, two files side by side), while
// rbsim/recording.hpp serves topics in log-time or step order.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <utility>
#include <variant>
#include <vector>

#include "rbsim/bag.hpp"
#include "rbsim/mcap.hpp"
#include "rbsim/status.hpp"

namespace rbsim::recordings {

// Reads one file, or a bag directory's files in order as one recording (rbsim/bag.hpp's BagJoin),
// on its own thread (decompression and CRCs are most of the work), every CRC
// verified, handing its Schema, Channel and Message records over in batches; at most kPumpBytes
// ahead of the consumer.
// Message buffers the consumer is done with come back through recycle() and are filled again:
// a fresh buffer per message costs a page fault per 4 KiB of message data.
class RecordStream {
 public:
  static constexpr std::uint64_t kPumpBytes = 1u << 20;
  static constexpr std::size_t kBatchRecords = 256;
  static constexpr std::uint64_t kBatchBytes = 256u << 10;
  static constexpr std::size_t kSpareBuffers = 64;         // kept for reuse at most ...
  static constexpr std::uint64_t kSpareBytes = 64u << 20;  // ... and their capacity at most

  ~RecordStream() { stop(); }

  // Opens `path` and starts the reader thread; errors name the file and what is wrong with it.
  [[nodiscard]] Status open(const std::string& path);
  void stop() {
    {
      std::lock_guard<std::mutex> lock(mu_);
      stop_ = true;
    }
    cv_.notify_all();
    if (thread_.joinable()) thread_.join();
  }
  // Gives a message buffer back for the reader thread to fill again (consumer side; handed over
  // with the next batch).
  void recycle(mcap::Bytes&& buffer) {
    if (buffer.capacity() == 0 || returned_.size() >= kSpareBuffers) return;
    returned_.push_back(std::move(buffer));
  }
  // The next record, or null at the end (then status() says whether the file was read whole).
  mcap::Record* next() {
    if (pos_ < current_.size()) return &current_[pos_++];
    current_.clear();
    pos_ = 0;
    std::unique_lock<std::mutex> lock(mu_);
    for (mcap::Bytes& b : returned_) {
      if (spare_.size() >= kSpareBuffers || spare_bytes_ + b.capacity() > kSpareBytes) break;
      spare_bytes_ += b.capacity();
      spare_.push_back(std::move(b));
    }
    returned_.clear();
    cv_.wait(lock, [&] { return !batches_.empty() || finished_; });
    if (batches_.empty()) return nullptr;
    current_ = std::move(batches_.front().first);
    queued_ -= batches_.front().second;
    batches_.pop_front();
    lock.unlock();
    cv_.notify_all();
    return current_.empty() ? next() : &current_[pos_++];
  }
  // Once next() returned null: Ok when the file was read whole, else the file and what is wrong.
  Status status() const;

 private:
  void run();
  bool keep(const mcap::Record& record);
  bool next_file();

  std::string path_;                // the file being read (guarded by mu_ once the thread runs)
  std::vector<std::string> files_;  // one, or a bag's
  std::size_t file_ = 0;            // reader thread: the file being read, its BagJoin, schemas seen
  BagJoin join_;
  std::set<std::uint16_t> schemas_;
  Status failure_ = Ok{};
  bool joined_ = false;
  mcap::StreamReader reader_;
  std::thread thread_;
  std::mutex mu_;
  std::condition_variable cv_;
  std::deque<std::pair<std::vector<mcap::Record>, std::uint64_t>> batches_;
  std::uint64_t queued_ = 0;
  bool stop_ = false, finished_ = false;
  Status status_;
  std::vector<mcap::Bytes> spare_;     // guarded by mu_: recycled buffers for the reader thread
  std::uint64_t spare_bytes_ = 0;      // their capacity
  std::vector<mcap::Record> current_;  // consumer side
  std::size_t pos_ = 0;
  std::vector<mcap::Bytes> returned_;  // consumer side: recycled since the last batch
};

}  // namespace rbsim::recordings
