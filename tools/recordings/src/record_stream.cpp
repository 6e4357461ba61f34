// The reader thread of a streamed recording (rbsim/record_stream.hpp).
#include "rbsim/record_stream.hpp"

#include <string>

#include "rbsim/bag.hpp"
#include "rbsim/mcap_tools.hpp"

namespace rbsim::recordings {

Status RecordStream::open(const std::string& given) {
  Result<std::vector<std::string>> files = recording_files(given);  // a bag directory: its files
  if (!files) return files.error();
  files_ = std::move(files.value());
  path_ = files_.front();
  // Missing, a directory or empty: worded as Recording words it.
  if (std::string e = mcap_tools::unreadable(path_); !e.empty()) return Error{path_ + ": " + e};
  if (const Status st = reader_.open(path_); !st.ok())
    return Error{path_ + ": " + mcap_tools::read_error(st.error())};
  thread_ = std::thread([this] { run(); });
  return Ok{};
}

Status RecordStream::status() const {
  if (status_.ok()) return Ok{};
  if (joined_) return status_;  // the bag's files disagree: the message names the file
  return Error{path_ + ": " + mcap_tools::read_error(status_.error())};
}

// A record of file `file_` to pass on: the files of a bag read as one (BagJoin), so a later file's
// repeats of schemas, channels and latched messages are skipped.
bool RecordStream::keep(const mcap::Record& record) {
  if (const auto* m = std::get_if<mcap::Message>(&record)) return !join_.repeated(file_, *m);
  if (const auto* s = std::get_if<mcap::Schema>(&record)) return schemas_.insert(s->id).second;
  if (const auto* c = std::get_if<mcap::Channel>(&record)) {
    bool repeat = false;
    if (Status st = join_.channel(file_, *c, repeat); !st) {
      joined_ = true;
      failure_ = with_context(files_[file_] + ": ", st.error(), ErrorCode::Malformed);
      return false;
    }
    return !repeat;
  }
  return false;
}

// At the end of a file: the next file of the bag, if the file was read whole and there is one.
bool RecordStream::next_file() {
  if (!reader_.status().ok() || !failure_.ok() || file_ + 1 >= files_.size()) return false;
  ++file_;
  std::lock_guard<std::mutex> lock(mu_);
  path_ = files_[file_];
  if (std::string e = mcap_tools::unreadable(path_); !e.empty()) {
    failure_ = Error{e};
  } else if (Status st = reader_.open(path_); !st.ok()) {
    failure_ = st;
  }
  return failure_.ok();
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
    bool more = reader_.next(entry);
    if (!more) more = next_file() && reader_.next(entry);
    if (more && keep(entry.record)) {
      if (const auto* m = std::get_if<mcap::Message>(&entry.record)) bytes += m->data.size();
      bytes += 64;
      batch.push_back(std::move(entry.record));
    }
    if (!failure_.ok()) more = false;
    if (!more || batch.size() >= kBatchRecords || bytes >= kBatchBytes) {
      std::unique_lock<std::mutex> lock(mu_);
      cv_.wait(lock, [&] { return stop_ || queued_ < kPumpBytes; });
      if (stop_) return;
      queued_ += bytes;
      batches_.emplace_back(std::move(batch), bytes);
      batch = {};
      bytes = 0;
      if (!more) {
        status_ = failure_.ok() ? reader_.status() : failure_;
        finished_ = true;
      }
      lock.unlock();
      cv_.notify_all();
      if (!more) return;
    }
  }
}

}  // namespace rbsim::recordings
