// The recorder: DDS topics to an MCAP file, byte for byte.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <numeric>
#include <optional>
#include <regex>

#include "rbsim/assert.hpp"
#include "rbsim/bag.hpp"
#include "rbsim/mcap_sink.hpp"
#include "rbsim/recorder.hpp"
#include "rbsim/time.hpp"

namespace rbsim::bag {

using namespace node;

namespace {
// How many samples of a latched topic a subscription holds between two polls.
constexpr std::int32_t kLatchedQueue = 256;
// Log times: the wall clock, unsigned as MCAP's.
std::uint64_t log_time_now() {
  return static_cast<std::uint64_t>(wall_ns());
}
}  // namespace

void Recorder::Gaps::add(std::int64_t stamp, double dt) {
  if (count > 0 && stamp <= last) {  // the scene started again (node --loop): close this run
    lost_before += lost(dt);
    count = 0;
  }
  if (count == 0) {
    first = last = stamp;
    stride = 0;
  } else {
    const std::int64_t d = stamp - last;
    stride = stride == 0 ? d : std::min(stride, d);
    last = stamp;
  }
  ++count;
}

std::uint64_t Recorder::Gaps::lost(double dt) const {
  if (count < 2 || stride <= 0) return 0;
  // In steps when dt is known (exact: a stamp is round(step * dt * 1e9)); else in ns, rounded.
  const double unit = dt > 0.0 ? dt * 1e9 : 1.0;
  const auto steps = [unit](std::int64_t ns) { return std::llround(static_cast<double>(ns) / unit); };
  const std::int64_t k = std::max<std::int64_t>(steps(stride), 1);
  const std::int64_t expected = (steps(last) - steps(first)) / k + 1;
  return expected > static_cast<std::int64_t>(count) ? static_cast<std::uint64_t>(expected) - count : 0;
}

namespace {
// The topics `options` choose, in msgs::topics() order (rosbag2's rule, RecorderOptions), by
// msgs::select_topics().
Result<std::vector<const msgs::TopicSpec*>> choose_topics(const RecorderOptions& options) {
  const std::vector<msgs::TopicCandidate> candidates = msgs::topic_candidates(options.ns, /*events=*/true);
  Result<std::vector<std::size_t>> chosen = msgs::select_topics(
      {options.topics, options.regex, options.exclude_topics, options.exclude_regex}, candidates);
  if (!chosen) return chosen.error();
  std::vector<const msgs::TopicSpec*> out;
  for (const std::size_t i : chosen.value()) out.push_back(candidates[i].spec);
  if (out.empty()) return Error{"the topic options choose no topic to record", ErrorCode::InvalidArgument};
  return out;
}
}  // namespace

Result<std::unique_ptr<Recorder>> Recorder::create(const Participant& participant,
                                                   const RecorderOptions& options) {
  std::unique_ptr<Recorder> r(new Recorder());
  r->options_ = options;
  Result<std::vector<const msgs::TopicSpec*>> chosen = choose_topics(options);
  if (!chosen) return chosen.error();
  std::vector<const msgs::TopicSpec*> wanted = std::move(chosen.value());
  // The node's --wait-for-subscribers watches the body-state topic: subscribe to it last, so
  // every other reader exists by the time the node starts publishing.
  std::stable_partition(wanted.begin(), wanted.end(),
                        [](const msgs::TopicSpec* s) { return s->id != msgs::TopicId::BodyStates; });
  if (options.snapshot_duration_ns == 0) {
    if (Status st = r->open_file(); !st) return st.error();
  }
  auto waitset = WaitSet::create(participant);
  if (!waitset) return waitset.error();
  r->waitset_ = std::move(waitset.value());
  // Before the topics of the table: the body states stay last (above).
  for (const node::RawTopic& raw : r->options_.raw_topics) {
    QosSpec qos;  // reliable, volatile (an event topic's writer offers no more), keep all
    qos.keep_all = true;
    auto sub = Subscription::create(participant, raw, qos);
    if (!sub) return with_context(raw.ros_name + ": ", sub.error());
    r->waitset_.attach(sub.value());
    r->topics_.push_back(Topic{std::move(sub.value()), &raw, 0, 0, {}, {}, 0, Gaps{}});
  }
  for (const msgs::TopicSpec* spec : wanted) {
    const std::string ros = msgs::topic_name(*spec, options.ns);
    // A latched topic's writer keeps its last sample for late joiners, but every change of the
    // world publishes a new scene description and markers (an epoch, rbsim/recording.hpp): the
    // reader's own queue holds many, so changes that come faster than the recorder polls all reach
    // the file.
    QosSpec qos = qos_for(*spec);
    if (qos.transient_local) qos.depth = kLatchedQueue;
    auto sub = Subscription::create(participant, *spec, ros, qos);
    if (!sub) return sub.error();
    r->waitset_.attach(sub.value());
    Topic topic{std::move(sub.value()), nullptr, 0, 0, {}, {}, 0, Gaps{}};
    topic.latched_pending = spec->latched();
    r->topics_.push_back(std::move(topic));
    if (spec->latched()) r->holding_ = true;
  }
  return r;
}

Result<std::uint16_t> Recorder::add_channel(const Topic& t, const msgs::OfferedQos& offered) {
  if (t.raw != nullptr) return recordings::add_topic(writer_, t.raw->ros_name, t.raw->ros_type, offered);
  return recordings::add_topic(writer_, t.subscription.spec(), options_.ns, offered);
}

// The next file: options.path, or the bag's file files_.size().
Status Recorder::open_file() {
  const std::string path =
      options_.bag.empty() ? options_.path : recordings::bag_file(options_.bag, files_.size());
  if (auto st = writer_.open(path, recordings::writer_options(options_.compression, options_.chunk_size,
                                                              options_.compression_level));
      !st.ok()) {
    return with_context(path + ": ", st.error());
  }
  options_.path = path;  // what errors name
  files_.push_back(path);
  file_start_ = 0;
  file_bytes_ = 0;
  return Ok{};
}

// Closes the open file of the bag and lists it in metadata.yaml (each file's summary read once).
Status Recorder::close_bag_file() {
  if (auto st = writer_.close(); !st.ok()) return with_context(options_.path + ": ", st.error());
  if (Status st = bag_metadata_.add(options_.path); !st) return st;
  return bag_metadata_.write(options_.bag);
}

// Closes the open file, lists it in the bag's metadata and opens the next, which defines every
// channel under its old id and starts with the latched topics' latest messages at `log_time`.
Status Recorder::split(std::uint64_t log_time) {
  if (Status st = close_bag_file(); !st) return st;
  if (Status st = open_file(); !st) return st;
  if (Status st = add_channels(); !st) return st;
  file_start_ = log_time;
  for (const std::size_t i : channel_order_) {
    Topic& t = topics_[i];
    if (!is_latched(t) || t.last.empty()) continue;
    if (auto st = writer_.write_message(t.channel, t.received - 1, log_time, t.last_source, t.last); !st.ok())
      return with_context(options_.path + ": ", st.error());
  }
  return Ok{};
}

// Every channel of the files before, in the order they were added: the same ids in every file.
Status Recorder::add_channels() {
  for (const std::size_t i : channel_order_) {
    Topic& t = topics_[i];
    auto channel = add_channel(t, t.offered);
    if (!channel.ok()) return with_context(options_.path + ": ", channel.error());
    if (channel.value() != t.channel) {
      return Error{options_.path + ": channel of " + t.subscription.ros_topic() + " got id " +
                   std::to_string(channel.value()) + ", not " + std::to_string(t.channel)};
    }
  }
  return Ok{};
}

Status Recorder::split_now() {
  if (options_.bag.empty() || options_.snapshot_duration_ns > 0) {
    return Error{"splitting needs a bag directory being recorded (not one .mcap file, not snapshot mode)",
                 ErrorCode::InvalidArgument};
  }
  if (file_start_ == 0) return Ok{};  // nothing in the open file yet: it stays the new one
  return split(std::max(file_start_, log_time_now()));
}

// Snapshot mode: the sample is kept (copied) instead of written; the oldest go once they are
// older than the duration or the payload is over its bound. Latched topics keep only their
// latest (Topic::last), written at the start of every snapshot.
void Recorder::keep(Topic& t, const Received& sample, std::uint64_t log_time, std::uint64_t source) {
  kept_.push_back({static_cast<std::size_t>(&t - topics_.data()),
                   msgs::Bytes(sample.cdr.begin(), sample.cdr.end()), log_time, source, t.received});
  kept_bytes_ += sample.cdr.size();
  while (!kept_.empty() && (kept_.front().log_time + options_.snapshot_duration_ns < log_time ||
                            kept_bytes_ > options_.snapshot_max_bytes)) {
    if (kept_.front().log_time + options_.snapshot_duration_ns >= log_time) ++snapshot_dropped_;
    kept_bytes_ -= kept_.front().cdr.size();
    kept_.pop_front();
  }
}

Result<std::uint64_t> Recorder::snapshot() {
  if (options_.snapshot_duration_ns == 0) {
    return Error{"not recording in snapshot mode (--snapshot-duration)", ErrorCode::InvalidArgument};
  }
  if (Status st = release_held(); !st) return st.error();
  if (kept_.empty()) return std::uint64_t{0};
  if (Status st = open_file(); !st) return st.error();
  if (Status st = add_channels(); !st) return st.error();
  std::uint64_t n = 0;
  const std::uint64_t first = kept_.front().log_time;
  for (const std::size_t i : channel_order_) {  // the latched topics' latest, at the first kept time
    Topic& t = topics_[i];
    if (!is_latched(t) || t.last.empty()) continue;
    if (auto st = writer_.write_message(t.channel, t.received - 1, first, t.last_source, t.last); !st.ok())
      return with_context(options_.path + ": ", st.error());
    ++n;
  }
  for (const Kept& k : kept_) {
    if (auto st = writer_.write_message(topics_[k.topic].channel, k.sequence, k.log_time, k.source, k.cdr);
        !st.ok())
      return with_context(options_.path + ": ", st.error());
    ++n;
  }
  kept_.clear();
  kept_bytes_ = 0;
  if (Status st = close_bag_file(); !st) return st.error();
  return n;
}

Recorder::~Recorder() = default;

Result<bool> Recorder::poll(std::int64_t timeout_ns) {
  if (Result<std::int32_t> n = waitset_.wait(timeout_ns); !n) return n.error();
  bool any = false;
  // A chunk compressed while no message came in reaches the file now, not at the next message.
  if (auto st = writer_.is_open() ? writer_.write_compressed_chunk() : Status(Ok{}); !st.ok())
    return with_context(options_.path + ": ", st.error());
  Received sample;
  for (Topic& t : topics_) {
    while (t.subscription.take(sample)) {
      if (paused()) {  // taken, so no writer waits on us, and not recorded
        ++skipped_paused_;
        any = true;
        continue;
      }
      any = true;
      auto newest = std::find_if(t.newest.begin(), t.newest.end(),
                                 [&](const auto& w) { return w.first == sample.writer; });
      if (newest != t.newest.end() && sample.source_time_ns <= newest->second) {
        ++t.duplicates;
        continue;
      }
      if (newest == t.newest.end()) {
        t.newest.emplace_back(sample.writer, sample.source_time_ns);
      } else {
        newest->second = sample.source_time_ns;
      }
      const std::uint64_t now = log_time_now();
      const std::size_t index = static_cast<std::size_t>(&t - topics_.data());
      const bool latched = is_latched(t);
      // Held: per-step samples while a latched topic is outstanding, and the markers while the
      // scene description is (it goes first).
      if (holding_ && (!latched || (!is_scene(t) && scene_pending()))) {
        held_bytes_ += sample.cdr.size();
        held_.push_back({index, std::move(sample), now});
        if (latched) t.latched_pending = false;  // it came: only its writing waits
        ++received_;
      } else {
        const std::uint64_t log_time = held_.empty() ? now : std::min(now, held_.front().log_time);
        if (Status st = write(t, sample, log_time); !st) return st.error();
        ++received_;
        t.latched_pending = false;
        if (holding_ && !latched_outstanding()) {
          holding_ = false;
          if (Status st = release_held(); !st) return st.error();
        }
      }
      if (options_.max_messages > 0 && received_ >= options_.max_messages) return any;
    }
  }
  // A latched topic that has no publisher any more need not be waited for; none after kHoldNs
  // (or kHoldBytes held): stop waiting (the readers find latched messages wherever they are).
  if (holding_ &&
      (!latched_outstanding() ||
       (!held_.empty() && (log_time_now() - held_.front().log_time > kHoldNs || held_bytes_ > kHoldBytes)))) {
    holding_ = false;
    if (Status st = release_held(); !st) return st.error();
  }
  RBSIM_ASSERT(holding_ || held_.empty(), "samples are held only while a latched topic is awaited");
  return any;
}

Status Recorder::write(Topic& t, const Received& sample, std::uint64_t log_time) {
  const bool latched = is_latched(t);
  const bool snapshots = options_.snapshot_duration_ns > 0;
  if (options_.max_file_bytes > 0 && ++written_ % 16 == 0) {  // the size as chunks reached the file
    std::error_code ec;
    file_bytes_ = std::filesystem::file_size(options_.path, ec);
    if (ec) file_bytes_ = 0;
  }
  if (!latched && !snapshots && file_start_ != 0 && !options_.bag.empty() &&
      ((options_.max_file_bytes > 0 && file_bytes_ >= options_.max_file_bytes) ||
       (options_.max_file_duration_ns > 0 && log_time >= file_start_ + options_.max_file_duration_ns))) {
    if (Status st = split(log_time); !st) return st;
  }
  if (file_start_ == 0) file_start_ = log_time;
  if (t.channel == 0) {  // like rosbag2: the channel says what the (first) publisher offers
    t.offered = sample.offered;
    channel_order_.push_back(static_cast<std::size_t>(&t - topics_.data()));
    if (snapshots) {  // no file open: the id add_channels() gives it (one schema and channel each, in order)
      t.channel = static_cast<std::uint16_t>(channel_order_.size());
    } else {
      auto channel = add_channel(t, sample.offered);
      if (!channel.ok()) return with_context(options_.path + ": ", channel.error());
      t.channel = channel.value();
    }
  }
  const std::uint64_t source =
      sample.source_time_ns > 0 ? static_cast<std::uint64_t>(sample.source_time_ns) : log_time;
  if (latched && !options_.bag.empty()) {
    t.last.assign(sample.cdr.begin(), sample.cdr.end());
    t.last_source = source;
  }
  if (snapshots) {
    if (!latched) keep(t, sample, log_time, source);
  } else if (auto st = writer_.write_message(t.channel, t.received, log_time, source, sample.cdr); !st.ok()) {
    return with_context(options_.path + ": ", st.error());
  }
  ++t.received;
  if (t.raw != nullptr) return Ok{};  // an event topic: no step to check
  const msgs::TopicId id = t.subscription.spec().id;
  if (id == msgs::TopicId::SceneDescription) {
    if (auto scene = msgs::decode_scene(sample.cdr); scene && scene.value().dt > 0.0) dt_ = scene.value().dt;
  } else if (!t.subscription.spec().per_step) {
    // latched or an event: no per-step sequence to check for gaps
  } else if (const auto stamp = msgs::decode_stamp(id, sample.cdr)) {
    t.gaps.add(static_cast<std::int64_t>(stamp->sec) * 1'000'000'000 + stamp->nanosec, dt_);
  }
  return Ok{};
}

bool Recorder::latched_outstanding() const {
  const bool scene_seen = !scene_pending();
  for (const Topic& t : topics_) {
    if (!t.latched_pending) continue;
    // The scene description is always waited for; other latched topics while a node offers them
    // (or until the scene description came, discovery of their writer having had that long).
    if (is_scene(t) || !scene_seen || t.subscription.matched() > 0) return true;
  }
  return false;
}

bool Recorder::scene_pending() const {
  return std::any_of(topics_.begin(), topics_.end(),
                     [](const Topic& t) { return t.latched_pending && is_scene(t); });
}

Status Recorder::release_held() {
  RBSIM_ASSERT(
      held_bytes_ == std::accumulate(held_.begin(), held_.end(), std::size_t{0},
                                     [](std::size_t n, const Held& h) { return n + h.sample.cdr.size(); }),
      "held_bytes_ counts the held samples' bytes");
  // Latched samples first, at the earliest held log time, so the file stays in log-time order.
  const std::uint64_t first = held_.empty() ? 0 : held_.front().log_time;
  for (const bool latched : {true, false}) {
    for (Held& h : held_) {
      Topic& t = topics_[h.topic];
      if (is_latched(t) != latched) continue;
      if (Status st = write(t, h.sample, latched ? first : h.log_time); !st) return st;
    }
  }
  held_.clear();
  held_bytes_ = 0;
  return Ok{};
}

std::vector<Recorder::TopicCount> Recorder::counts() const {
  std::vector<TopicCount> out;
  for (const Topic& t : topics_) {
    out.push_back({t.subscription.ros_topic(), t.received,
                   t.subscription.lost() + t.gaps.lost_before + t.gaps.lost(dt_)});
  }
  return out;
}

Status Recorder::close() {
  if (Status st = release_held(); !st) return st;
  if (options_.snapshot_duration_ns > 0)
    return Ok{};  // what a snapshot did not take is dropped, as rosbag2's
  if (!options_.bag.empty() && received_ > 0) return close_bag_file();
  if (auto st = writer_.close(); !st.ok()) return with_context(options_.path + ": ", st.error());
  return Ok{};
}

}  // namespace rbsim::bag
