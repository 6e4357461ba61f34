// The recorder: DDS topics to an MCAP file, byte for byte.
#include <dds/dds.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "rbsim/mcap_sink.hpp"
#include "rbsim/recorder.hpp"

namespace rbsim::node {

namespace {
std::uint64_t wall_ns() {
  return static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                        std::chrono::system_clock::now().time_since_epoch())
                                        .count());
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

Result<std::unique_ptr<Recorder>> Recorder::create(const Participant& participant,
                                                   const RecorderOptions& options) {
  std::unique_ptr<Recorder> r(new Recorder());
  r->options_ = options;
  std::vector<const msgs::TopicSpec*> wanted;
  if (options.topics.empty()) {
    for (const msgs::TopicSpec& spec : msgs::topics()) wanted.push_back(&spec);
  } else {
    for (const std::string& name : options.topics) {
      const msgs::TopicSpec* spec = find_topic(name, options.ns);
      if (spec == nullptr) {
        std::string known;
        for (const msgs::TopicSpec& s : msgs::topics())
          known += (known.empty() ? "" : ", ") + msgs::topic_name(s, options.ns);
        return Error{"unknown topic \"" + name + "\" (rbsim topics: " + known + ")"};
      }
      wanted.push_back(spec);
    }
  }
  // The node's --wait-for-subscribers watches the body-state topic: subscribe to it last, so
  // every other reader exists by the time the node starts publishing.
  std::stable_partition(wanted.begin(), wanted.end(),
                        [](const msgs::TopicSpec* s) { return s->id != msgs::TopicId::BodyStates; });
  if (auto st = r->writer_.open(options.path, log::writer_options(options.compression, options.chunk_size,
                                                                  options.compression_level));
      !st.ok()) {
    return Error{options.path + ": " + st.error().message};
  }
  r->waitset_ = dds_create_waitset(participant.handle());
  for (const msgs::TopicSpec* spec : wanted) {
    const std::string ros = msgs::topic_name(*spec, options.ns);
    auto sub = Subscription::create(participant, *spec, ros, qos_for(*spec));
    if (!sub) return sub.error();
    dds_waitset_attach(r->waitset_, sub->reader(), static_cast<dds_attach_t>(r->topics_.size()));
    r->topics_.push_back(Topic{std::move(sub.value()), 0, 0, Gaps{}});
    r->latched_pending_.push_back(spec->latched());
    if (spec->latched()) r->holding_ = true;
  }
  return r;
}

Recorder::~Recorder() {
  if (waitset_ > 0) dds_delete(waitset_);
}

Result<bool> Recorder::poll(std::int64_t timeout_ns) {
  dds_attach_t triggered[16];
  const dds_return_t n = dds_waitset_wait(waitset_, triggered, 16, timeout_ns);
  if (n < 0) return Error{std::string("DDS wait failed: ") + dds_strretcode(n)};
  bool any = false;
  // A chunk compressed while no message came in reaches the file now, not at the next message.
  if (auto st = writer_.write_compressed_chunk(); !st.ok())
    return Error{options_.path + ": " + st.error().message};
  Received sample;
  for (Topic& t : topics_) {
    while (t.subscription.take(sample)) {
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
      const std::uint64_t now = wall_ns();
      const std::size_t index = static_cast<std::size_t>(&t - topics_.data());
      const bool latched = t.subscription.spec().latched();
      // Held: per-step samples while a latched topic is outstanding, and the markers while the
      // scene description is (it goes first).
      if (holding_ && (!latched || (t.subscription.spec().id != msgs::TopicId::Scene && scene_pending()))) {
        held_bytes_ += sample.cdr.size();
        held_.push_back({index, std::move(sample), now});
        if (latched) latched_pending_[index] = false;  // it came: only its writing waits
        ++received_;
      } else {
        const std::uint64_t log_time = held_.empty() ? now : std::min(now, held_.front().log_time);
        if (Status st = write(t, sample, log_time); !st) return st.error();
        ++received_;
        latched_pending_[index] = false;
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
       (!held_.empty() && (wall_ns() - held_.front().log_time > kHoldNs || held_bytes_ > kHoldBytes)))) {
    holding_ = false;
    if (Status st = release_held(); !st) return st.error();
  }
  return any;
}

Status Recorder::write(Topic& t, const Received& sample, std::uint64_t log_time) {
  if (t.channel == 0) {  // like rosbag2: the channel says what the (first) publisher offers
    auto channel = log::add_topic(writer_, t.subscription.spec(), options_.ns, sample.offered);
    if (!channel.ok()) return Error{options_.path + ": " + channel.error().message};
    t.channel = channel.value();
  }
  const std::uint64_t source =
      sample.source_time_ns > 0 ? static_cast<std::uint64_t>(sample.source_time_ns) : log_time;
  if (auto st = writer_.write_message(t.channel, t.received, log_time, source, sample.cdr); !st.ok()) {
    return Error{options_.path + ": " + st.error().message};
  }
  ++t.received;
  const msgs::TopicId id = t.subscription.spec().id;
  if (id == msgs::TopicId::Scene) {
    if (auto scene = msgs::decode_scene(sample.cdr); scene && scene.value().dt > 0.0) dt_ = scene.value().dt;
  } else if (!t.subscription.spec().per_step) {
    // latched or an event: no per-step sequence to check for gaps
  } else if (const auto stamp = msgs::decode_stamp(id, sample.cdr)) {
    t.gaps.add(static_cast<std::int64_t>(stamp->sec) * 1'000'000'000 + stamp->nanosec, dt_);
  }
  return Ok{};
}

bool Recorder::latched_outstanding() const {
  bool scene_seen = true;
  for (std::size_t i = 0; i < topics_.size(); ++i) {
    if (latched_pending_[i] && topics_[i].subscription.spec().id == msgs::TopicId::Scene) scene_seen = false;
  }
  for (std::size_t i = 0; i < topics_.size(); ++i) {
    if (!latched_pending_[i]) continue;
    // The scene description is always waited for; other latched topics while a node offers them
    // (or until the scene description came, discovery of their writer having had that long).
    if (topics_[i].subscription.spec().id == msgs::TopicId::Scene || !scene_seen ||
        topics_[i].subscription.matched() > 0)
      return true;
  }
  return false;
}

bool Recorder::scene_pending() const {
  for (std::size_t i = 0; i < topics_.size(); ++i) {
    if (latched_pending_[i] && topics_[i].subscription.spec().id == msgs::TopicId::Scene) return true;
  }
  return false;
}

Status Recorder::release_held() {
  // Latched samples first, at the earliest held log time, so the file stays in log-time order.
  const std::uint64_t first = held_.empty() ? 0 : held_.front().log_time;
  for (const bool latched : {true, false}) {
    for (Held& h : held_) {
      Topic& t = topics_[h.topic];
      if (t.subscription.spec().latched() != latched) continue;
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
  if (auto st = writer_.close(); !st.ok()) return Error{options_.path + ": " + st.error().message};
  return Ok{};
}

}  // namespace rbsim::node
