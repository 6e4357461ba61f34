// The reader thread of a streamed recording (rbsim/record_stream.hpp).
#include "rbsim/record_stream.hpp"

#include "rbsim/mcap_tools.hpp"

namespace rbsim::log {

Status RecordStream::open(const std::string& path) {
  path_ = path;
  if (const Status st = reader_.open(path); !st.ok())
    return Error{path + ": " + mcap_tools::read_error(st.error())};
  thread_ = std::thread([this] { run(); });
  return Ok{};
}

Status RecordStream::status() const {
  if (status_.ok()) return Ok{};
  return Error{path_ + ": " + mcap_tools::read_error(status_.error())};
}

void RecordStream::run() {
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

}  // namespace rbsim::log
