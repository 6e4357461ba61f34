// rbsim log filter | merge | compress (rbsim/rewrite.hpp): messages read through Recording, in
// log-time order, written through one deduplicating Output.
#include "rbsim/rewrite.hpp"

#include <algorithm>
#include <condition_variable>
#include <deque>
#include <functional>
#include <future>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <thread>
#include <tuple>

#include "rbsim/atomic_file.hpp"
#include "rbsim/counts.hpp"
#include "rbsim/mcap_sink.hpp"
#include "rbsim/mcap_tools.hpp"
#include "rbsim/recording.hpp"
#include "select.hpp"

namespace rbsim::recordings {

namespace {

// The output file: identical schemas and channels written once, messages through one writer into
// an AtomicFile's temporary, renamed into place by close().
class Output {
 public:
  Status open(const std::string& path, const std::string& profile, const OutputOptions& options) {
    path_ = path;
    file_.open_external(path, AtomicFile::Leftovers::Remove);  // a killed rewrite is redone, not recovered
    mcap::WriterOptions wo = writer_options(options.compression, options.chunk_size);
    wo.profile = profile;
    if (Status st = writer_.open(file_.writer_path(), wo); !st.ok()) return fail(st.error());
    return Ok{};
  }

  // The output channel for `c` under `topic`: a channel already written with the same topic,
  // encoding, schema and metadata, or a new one (with its schema, if new).
  Result<std::uint16_t> channel(const RecordedChannel& c, const std::string& topic) {
    std::uint16_t schema_id = 0;
    if (c.schema != nullptr) {
      auto [it, fresh] = schemas_.try_emplace({c.schema->name, c.schema->encoding, c.schema->data}, 0);
      if (fresh) {
        auto id = writer_.add_schema(c.schema->name, c.schema->encoding, c.schema->data);
        if (!id) return fail(id.error());
        it->second = id.value();
        ++report_.schemas;
      }
      schema_id = it->second;
    }
    auto [it, fresh] =
        channels_.try_emplace({topic, c.channel->message_encoding, schema_id, c.channel->metadata}, 0);
    if (fresh) {
      auto id = writer_.add_channel(schema_id, topic, c.channel->message_encoding, c.channel->metadata);
      if (!id) return fail(id.error());
      it->second = id.value();
      ++report_.channels;
      if (topics_.insert(topic).second) report_.topics.push_back(topic);
    }
    return it->second;
  }

  // `c` with its own id and its schema's (a filter of one file keeps them, so whole chunks can be
  // copied).
  Result<std::uint16_t> same_channel(const RecordedChannel& c) {
    mcap::Channel channel = *c.channel;
    if (c.schema != nullptr) {
      if (Status st = writer_.add_schema(*c.schema); !st.ok()) return fail(st.error());
      if (schema_ids_.insert(c.schema->id).second) ++report_.schemas;
    } else {
      channel.schema_id = 0;
    }
    if (Status st = writer_.add_channel(channel); !st.ok()) return fail(st.error());
    ++report_.channels;
    if (topics_.insert(channel.topic).second) report_.topics.push_back(channel.topic);
    return channel.id;
  }

  // A whole chunk of the input, as stored.
  Status copy(const Recording::RawChunk& raw) {
    if (Status st = writer_.copy_chunk(raw.chunk, raw.indexes); !st.ok()) return fail(st.error());
    for (const mcap::MessageIndex& mi : raw.indexes) report_.messages += mi.records.size();
    ++report_.copied_chunks;
    return Ok{};
  }

  Status write(std::uint16_t channel, const mcap::Message& m, ByteView data) {
    if (Status st = writer_.write_message(channel, m.sequence, m.log_time, m.publish_time, data); !st.ok())
      return fail(st.error());
    ++report_.messages;
    return Ok{};
  }
  RewriteReport& report() { return report_; }

  Result<RewriteReport> close() {
    if (Status st = writer_.close(); !st.ok()) return fail(st.error());
    if (Status st = file_.commit(); !st) return st.error();
    return report_;
  }

 private:
  Error fail(const Error& e) const { return Error{path_ + ": " + e.message}; }

  std::string path_;
  AtomicFile file_;  // declared before writer_: the writer closes before the temporary is removed
  mcap::Writer writer_;
  std::map<std::tuple<std::string, std::string, Bytes>, std::uint16_t> schemas_;
  std::map<std::tuple<std::string, std::string, std::uint16_t, mcap::KeyValueMap>, std::uint16_t> channels_;
  std::set<std::string> topics_;
  std::set<std::uint16_t> schema_ids_;
  RewriteReport report_;
};

// Input channel id -> output channel id (0: not written), decided once per channel.
class Routes {
 public:
  // `decide` returns the output channel of an input channel (0: dropped).
  template <typename Decide>
  Result<std::uint16_t> route(const RecordedChannel& c, Decide&& decide) {
    std::int32_t& r = routes_[c.channel->id];
    if (r < 0) {
      Result<std::uint16_t> id = decide(c);
      if (!id) return id.error();
      r = id.value();
    }
    return static_cast<std::uint16_t>(r);
  }

 private:
  std::vector<std::int32_t> routes_ = std::vector<std::int32_t>(65536, -1);
};

Result<std::unique_ptr<Recording>> open_input(const std::string& path) {
  return Recording::open(path, raw_options());  // every topic as recorded, whatever its type
}

// The last message before `start` of every latched channel `keep` keeps, in log-time order.
Result<std::vector<std::pair<const RecordedChannel*, mcap::Message>>> latched_before(
    Recording& recording, mcap::Timestamp start, const std::function<bool(const std::string&)>& keep) {
  std::map<const RecordedChannel*, mcap::Message> last;
  MessageFilter filter;
  for (const RecordedChannel& c : recording.channels()) {
    if (c.spec != nullptr && c.spec->latched() && keep(c.channel->topic))
      filter.topics.push_back(c.channel->topic);
  }
  std::vector<std::pair<const RecordedChannel*, mcap::Message>> out;
  if (filter.topics.empty() || start == 0) return out;
  filter.end = start;
  const Status st = recording.read_messages(filter, [&](const RecordedMessage& m) {
    if (m.channel->spec != nullptr && m.channel->spec->latched()) last[m.channel] = *m.message;
    return true;
  });
  if (!st) return st.error();
  for (auto& [channel, message] : last) out.emplace_back(channel, std::move(message));
  std::stable_sort(out.begin(), out.end(),
                   [](const auto& a, const auto& b) { return a.second.log_time < b.second.log_time; });
  return out;
}

// The chunks a filter copies whole: inside the window, every channel kept, compressed as the
// output is, spanning more than one log time, and no other chunk holding a time strictly inside
// theirs (a neighbour may share their first or last time: a chunk boundary within one step), so
// log-time order holds around them; by start time. None when the file's chunks may hold channels
// its summary lacks.
std::vector<const mcap::ChunkIndex*> whole_chunks(const Recording& recording, mcap::Timestamp start,
                                                  mcap::Timestamp end, const std::set<std::uint16_t>& kept,
                                                  mcap::Compression compression) {
  std::vector<const mcap::ChunkIndex*> all, out;
  if (!recording.lists_every_channel()) return out;
  for (const mcap::ChunkIndex& ci : recording.chunk_indexes()) all.push_back(&ci);
  std::stable_sort(all.begin(), all.end(), [](const mcap::ChunkIndex* a, const mcap::ChunkIndex* b) {
    return a->message_start_time < b->message_start_time;
  });
  std::optional<mcap::Timestamp> end_before;  // the latest end of the chunks before
  for (std::size_t i = 0; i < all.size(); ++i) {
    const mcap::ChunkIndex& ci = *all[i];
    const bool overlaps = (end_before && *end_before > ci.message_start_time) ||
                          (i + 1 < all.size() && all[i + 1]->message_start_time < ci.message_end_time);
    end_before = std::max(end_before.value_or(0), ci.message_end_time);
    if (overlaps || ci.message_start_time >= ci.message_end_time ||
        ci.compression != mcap::to_string(compression) || ci.message_start_time < start ||
        ci.message_end_time >= end || ci.message_index_offsets.empty())
      continue;
    bool all_kept = true;
    for (const auto& [channel_id, offset] : ci.message_index_offsets)
      all_kept = all_kept && kept.count(channel_id) > 0;
    if (all_kept) out.push_back(&ci);
  }
  return out;
}

}  // namespace

std::string RewriteReport::summary(const std::string& out) const {
  std::string s = "wrote " + out + ": " + group_digits(messages) + plural(messages, " message", " messages");
  if (latched > 0) s += " (" + group_digits(latched) + " latched from before the window)";
  s += " on " + group_digits(topics.size()) + plural(topics.size(), " topic, ", " topics, ");
  s += group_digits(channels) + plural(channels, " channel, ", " channels, ");
  s += group_digits(schemas) + plural(schemas, " schema", " schemas");
  if (copied_chunks > 0)
    s += "; " + group_digits(copied_chunks) + plural(copied_chunks, " chunk", " chunks") + " copied whole";
  s += '\n';
  return s;
}

namespace {

// Copies the chunks `whole` as stored, and through `copy_messages` (from, to) the messages before
// each of them; `cursor` moves past each one copied.
Status copy_whole_chunks(const std::string& in, Recording& recording, Output& output,
                         const std::vector<const mcap::ChunkIndex*>& whole,
                         const std::function<Status(mcap::Timestamp, mcap::Timestamp)>& copy_messages,
                         mcap::Timestamp& cursor) {
  // Each copied chunk's CRC is checked (the chunk decompressed) while the copying goes on: every
  // other chunk on a second thread, the rest on this one after its copy, so two cores share the
  // checks; the output is committed only once every check passed.
  struct Lane {
    mcap::ChunkDecompressor decompressor;
    Bytes records;
  };
  Lane here, there;
  const auto check = [&in](Lane& lane, const mcap::Chunk& chunk, std::uint64_t offset) -> Status {
    if (Status st = lane.decompressor.decompress(chunk, lane.records, true); !st.ok())
      return Error{in + ": chunk at offset " + std::to_string(offset) + ": " +
                   mcap_tools::read_error(st.error())};
    return Ok{};
  };
  std::future<Status> checked;
  for (std::size_t i = 0; i < whole.size(); ++i) {
    const mcap::ChunkIndex& ci = *whole[i];
    if (Status st = copy_messages(cursor, ci.message_start_time + 1); !st) return st.error();
    auto raw = recording.read_chunk(ci, false);
    if (!raw) return raw.error();
    if (Status st = output.copy(raw.value()); !st) return st.error();
    cursor = ci.message_end_time;
    if (i % 2 == 1) {
      if (Status st = check(here, raw.value().chunk, ci.chunk_start_offset); !st) return st.error();
      continue;
    }
    if (checked.valid()) {
      if (Status st = checked.get(); !st) return st.error();
    }
    checked = std::async(
        std::launch::async,
        [&check, &there, offset = ci.chunk_start_offset, chunk = std::move(raw.value().chunk)]() -> Status {
          return check(there, chunk, offset);
        });
  }
  if (checked.valid()) {
    if (Status st = checked.get(); !st) return st.error();
  }
  return Ok{};
}

// filter() and compress(): with copy_chunks, whole chunks inside the window are copied as stored.
Result<RewriteReport> filter_file(const std::string& in, const std::string& out, const FilterOptions& options,
                                  bool copy_chunks) {
  if (!options.topics.empty() && !options.exclude_topics.empty())
    return Error{in + ": topics to keep and topics to leave out: give one or the other"};
  const mcap::Timestamp start = detail::to_ns(options.start).value_or(0);
  const mcap::Timestamp end = detail::to_ns(options.end).value_or(mcap::kMaxTime);
  if (end < start) return Error{in + ": the window ends before it starts (end < start)"};
  auto opened = open_input(in);
  if (!opened) return opened.error();
  Recording& recording = *opened.value();
  auto include = detail::choose_topics(recording, options.topics);
  if (!include) return include.error();
  auto exclude = detail::choose_topics(recording, options.exclude_topics);
  if (!exclude) return exclude.error();
  const std::set<std::string> kept(include.value().begin(), include.value().end());
  const std::set<std::string> left(exclude.value().begin(), exclude.value().end());
  const auto keep = [&](const std::string& topic) {
    return (kept.empty() || kept.count(topic) > 0) && left.count(topic) == 0;
  };

  Output output;
  if (Status st = output.open(out, recording.header().profile, options.output); !st) return st.error();
  Routes routes;
  std::set<std::uint16_t> kept_ids;
  const auto decide = [&](const RecordedChannel& c) -> Result<std::uint16_t> {
    if (!keep(c.channel->topic)) return std::uint16_t{0};
    kept_ids.insert(c.channel->id);
    return output.same_channel(c);
  };
  for (const RecordedChannel& c :
       recording.channels()) {  // every kept channel listed, with or without messages
    if (auto r = routes.route(c, decide); !r) return r.error();
  }
  auto latched = latched_before(recording, start, keep);
  if (!latched) return latched.error();
  for (const auto& [channel, message] : latched.value()) {
    auto id = routes.route(*channel, decide);
    if (!id) return id.error();
    if (Status st = output.write(id.value(), message, message.data); !st) return st.error();
    ++output.report().latched;
  }

  MessageFilter selection;
  if (!kept.empty() || !left.empty()) {
    for (const RecordedChannel& c : recording.channels()) {
      if (keep(c.channel->topic)) selection.topics.push_back(c.channel->topic);
    }
    if (selection.topics.empty()) return output.close();  // nothing kept: channels only
  }
  const auto copy_messages = [&](mcap::Timestamp from, mcap::Timestamp to) -> Status {
    selection.start = from;
    selection.end = to;
    Status failure = Ok{};
    const Status read = recording.read_messages(selection, [&](const RecordedMessage& m) {
      auto id = routes.route(*m.channel, decide);
      if (!id) failure = id.error();
      if (id && id.value() != 0) failure = output.write(id.value(), *m.message, m.cdr());
      return static_cast<bool>(failure);
    });
    return read ? failure : read;
  };
  // Whole chunks are copied as stored, and the messages between them read and written: those
  // sharing a copied chunk's first time before it, its last time after it (file order at ties).
  mcap::Timestamp cursor = start;
  if (copy_chunks) {
    const auto whole = whole_chunks(recording, start, end, kept_ids, options.output.compression);
    for (const mcap::ChunkIndex* ci : whole) selection.skip_chunks.push_back(ci->chunk_start_offset);
    if (Status st = copy_whole_chunks(in, recording, output, whole, copy_messages, cursor); !st)
      return st.error();
  }
  if (Status st = copy_messages(cursor, end); !st) return st.error();
  return output.close();
}

}  // namespace

Result<RewriteReport> filter(const std::string& in, const std::string& out, const FilterOptions& options) {
  return filter_file(in, out, options, true);
}

Result<RewriteReport> compress(const std::string& in, const std::string& out, const OutputOptions& output) {
  FilterOptions options;
  options.output = output;
  return filter_file(in, out, options, false);  // re-chunked: every chunk written anew
}

namespace {

// One input's messages in log-time order, read by Recording::read_messages on a thread of its
// own and handed over in batches (at most kQueueBytes ahead), so several inputs can be merged.
class Pump {
 public:
  static constexpr std::size_t kBatchMessages = 1024;
  static constexpr std::size_t kBatchBytes = 256u << 10;
  static constexpr std::size_t kQueueBytes = 4u << 20;

  struct Item {
    const RecordedChannel* channel = nullptr;
    mcap::Message message;  // data empty: the bytes are data() of the batch
    std::size_t offset = 0, size = 0;
  };

  explicit Pump(Recording& recording) : recording_(recording) {}
  ~Pump() {
    {
      std::lock_guard<std::mutex> lock(mu_);
      stop_ = true;
    }
    cv_.notify_all();
    if (thread_.joinable()) thread_.join();
  }
  void start() {
    thread_ = std::thread([this] { run(); });
  }

  // The next message, or null at the end (then status()).
  const Item* peek() {
    if (pos_ < current_.items.size()) return &current_.items[pos_];
    std::unique_lock<std::mutex> lock(mu_);
    cv_.wait(lock, [&] { return !queue_.empty() || finished_; });
    if (queue_.empty()) return nullptr;
    current_ = std::move(queue_.front());
    queue_.pop_front();
    queued_ -= current_.data.size();
    pos_ = 0;
    lock.unlock();
    cv_.notify_all();
    return peek();
  }
  void pop() { ++pos_; }
  ByteView data(const Item& item) const { return ByteView(current_.data).subspan(item.offset, item.size); }
  Status status() {
    std::lock_guard<std::mutex> lock(mu_);
    return status_;
  }

 private:
  struct Batch {
    std::vector<Item> items;
    Bytes data;
  };

  bool hand_over(Batch& batch) {
    std::unique_lock<std::mutex> lock(mu_);
    cv_.wait(lock, [&] { return stop_ || queued_ < kQueueBytes; });
    if (stop_) return false;
    queued_ += batch.data.size();
    queue_.push_back(std::move(batch));
    batch = {};
    lock.unlock();
    cv_.notify_all();
    return true;
  }

  void run() {
    Batch batch;
    bool stopped = false;
    const Status st = recording_.read_messages({}, [&](const RecordedMessage& m) {
      Item item{m.channel, {}, batch.data.size(), m.cdr().size()};
      item.message.channel_id = m.message->channel_id;
      item.message.sequence = m.message->sequence;
      item.message.log_time = m.message->log_time;
      item.message.publish_time = m.message->publish_time;
      batch.data.insert(batch.data.end(), m.cdr().begin(), m.cdr().end());
      batch.items.push_back(std::move(item));
      if (batch.items.size() >= kBatchMessages || batch.data.size() >= kBatchBytes)
        stopped = !hand_over(batch);
      return !stopped;
    });
    if (!stopped && !batch.items.empty()) hand_over(batch);
    std::lock_guard<std::mutex> lock(mu_);
    status_ = st;
    finished_ = true;
    cv_.notify_all();
  }

  Recording& recording_;
  std::thread thread_;
  std::mutex mu_;
  std::condition_variable cv_;
  std::deque<Batch> queue_;  // guarded by mu_
  std::size_t queued_ = 0;
  bool stop_ = false, finished_ = false;
  Status status_;
  Batch current_;  // consumer side
  std::size_t pos_ = 0;
};

// "" for none ("/" or empty), else the namespace without a trailing '/'.
std::string prefix_of(const std::vector<std::string>& namespaces, std::size_t i) {
  if (namespaces.empty()) return "";
  std::string ns = namespaces[i];
  while (!ns.empty() && ns.back() == '/') ns.pop_back();
  if (!ns.empty() && ns.front() != '/') ns.insert(ns.begin(), '/');
  return ns;
}

// Refuses inputs whose scene descriptions share an output topic but differ (different scenes).
Status check_scenes(const std::vector<std::unique_ptr<Recording>>& inputs,
                    const std::vector<std::string>& prefixes) {
  std::map<std::string, std::pair<std::size_t, Bytes>> seen;  // output topic -> first input, scene
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    Recording& r = *inputs[i];
    for (const RecordedChannel& c : r.channels()) {
      if (c.spec == nullptr || c.spec->id != msgs::TopicId::SceneDescription) continue;
      MessageFilter filter;
      filter.topics = {c.channel->topic};
      std::optional<Bytes> scene;
      const Status st = r.read_messages(filter, [&](const RecordedMessage& m) {
        if (m.channel == &c) scene = Bytes(m.cdr().begin(), m.cdr().end());
        return !scene;
      });
      if (!st) return st;
      if (!scene) continue;
      const std::string topic = prefixes[i] + c.channel->topic;
      const auto [it, fresh] = seen.try_emplace(topic, i, *scene);
      if (!fresh && it->second.second != *scene) {
        return Error{inputs[it->second.first]->path() + " and " + r.path() + " record different scenes on " +
                     topic +
                     ": one file holds one scene per topic (give each input a namespace of its own: "
                     "--namespaces)"};
      }
    }
  }
  return Ok{};
}

}  // namespace

Result<RewriteReport> merge(const std::vector<std::string>& inputs, const std::string& out,
                            const MergeOptions& options) {
  if (inputs.empty()) return Error{out + ": nothing to merge (no input)"};
  if (!options.namespaces.empty() && options.namespaces.size() != inputs.size()) {
    return Error{out + ": " + std::to_string(options.namespaces.size()) + " namespaces for " +
                 std::to_string(inputs.size()) + " inputs: give one per input (\"/\" for none)"};
  }
  std::vector<std::unique_ptr<Recording>> recordings;
  std::vector<std::string> prefixes;
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    auto opened = open_input(inputs[i]);
    if (!opened) return opened.error();
    recordings.push_back(std::move(opened.value()));
    prefixes.push_back(prefix_of(options.namespaces, i));
  }
  if (Status st = check_scenes(recordings, prefixes); !st) return st.error();

  Output output;
  if (Status st = output.open(out, recordings.front()->header().profile, options.output); !st)
    return st.error();
  std::vector<Routes> routes(inputs.size());
  std::vector<std::unique_ptr<Pump>> pumps;
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    for (const RecordedChannel& c : recordings[i]->channels()) {
      if (auto r = routes[i].route(
              c,
              [&](const RecordedChannel& rc) { return output.channel(rc, prefixes[i] + rc.channel->topic); });
          !r)
        return r.error();
    }
    pumps.push_back(std::make_unique<Pump>(*recordings[i]));
    pumps.back()->start();
  }
  for (;;) {
    std::size_t best = pumps.size();
    mcap::Timestamp best_time = 0;
    for (std::size_t i = 0; i < pumps.size(); ++i) {  // the earliest; equal times: the first input
      const Pump::Item* item = pumps[i]->peek();
      if (item != nullptr && (best == pumps.size() || item->message.log_time < best_time)) {
        best = i;
        best_time = item->message.log_time;
      }
    }
    if (best == pumps.size()) break;
    Pump& pump = *pumps[best];
    const Pump::Item& item = *pump.peek();
    auto id = routes[best].route(*item.channel, [&](const RecordedChannel& rc) {
      return output.channel(rc, prefixes[best] + rc.channel->topic);
    });
    if (!id) return id.error();
    if (Status st = output.write(id.value(), item.message, pump.data(item)); !st) return st.error();
    pump.pop();
  }
  for (auto& pump : pumps) {
    if (Status st = pump->status(); !st) return st.error();
  }
  return output.close();
}

}  // namespace rbsim::recordings
