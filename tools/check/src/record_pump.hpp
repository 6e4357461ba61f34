// rbsim check's reader thread: one MCAP file streamed on its own thread (decompression and CRCs
// are most of the work of a check), its records handed over in batches.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <mutex>
#include <string>
#include <thread>
#include <utility>
#include <variant>
#include <vector>

#include "rbsim/mcap.hpp"

namespace rbsim::check {

// Reads one file on its own thread (decompression and CRCs are most of the work), handing its
// Schema, Channel and Message records over in batches; at most kPumpBytes ahead of the consumer.
// Message buffers the consumer is done with come back through recycle() and are filled again:
// a fresh buffer per message costs a page fault per 4 KiB of message data.
class RecordPump {
 public:
  static constexpr std::uint64_t kPumpBytes = 1u << 20;
  static constexpr std::size_t kBatchRecords = 256;
  static constexpr std::uint64_t kBatchBytes = 256u << 10;
  static constexpr std::size_t kSpareBuffers = 64;         // kept for reuse at most ...
  static constexpr std::uint64_t kSpareBytes = 64u << 20;  // ... and their capacity at most

  ~RecordPump() { stop(); }

  Status open(const std::string& path) {
    Status st = reader_.open(path);
    if (st.ok()) thread_ = std::thread([this] { run(); });
    return st;
  }
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
  const Status& status() const { return status_; }  // valid once next() returned null

 private:
  void run() {
    mcap::RecordEntry entry;
    std::vector<mcap::Record> batch;
    std::uint64_t bytes = 0;
    std::vector<mcap::Bytes> spare;  // buffers to fill, taken from spare_
    for (;;) {
      if (auto* m = std::get_if<mcap::Message>(&entry.record); m != nullptr && m->data.capacity() == 0) {
        if (spare.empty()) {
          std::lock_guard<std::mutex> lock(mu_);
          spare.swap(spare_);
          spare_bytes_ = 0;
        }
        if (!spare.empty()) {
          m->data = std::move(spare.back());
          spare.pop_back();
        }
      }
      const bool more = reader_.next(entry);
      if (more) {
        if (const auto* m = std::get_if<mcap::Message>(&entry.record)) {
          bytes += m->data.size() + 64;
          batch.push_back(std::move(entry.record));
        } else if (std::holds_alternative<mcap::Schema>(entry.record) ||
                   std::holds_alternative<mcap::Channel>(entry.record)) {
          bytes += 64;
          batch.push_back(std::move(entry.record));
        }
      }
      if (!more || batch.size() >= kBatchRecords || bytes >= kBatchBytes) {
        std::unique_lock<std::mutex> lock(mu_);
        cv_.wait(lock, [&] { return stop_ || queued_ < kPumpBytes; });
        if (stop_) return;
        queued_ += bytes;
        batches_.emplace_back(std::move(batch), bytes);
        batch = {};
        bytes = 0;
        if (!more) {
          status_ = reader_.status();
          finished_ = true;
        }
        lock.unlock();
        cv_.notify_all();
        if (!more) return;
      }
    }
  }

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

}  // namespace rbsim::check
