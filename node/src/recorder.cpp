// The recorder: DDS topics to an MCAP file, byte for byte.
#include <dds/dds.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "rbsim/record.hpp"
#include "rbsim/recorder.hpp"

namespace rbsim::node {

namespace {
std::uint64_t wall_ns() {
  return static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                        std::chrono::system_clock::now().time_since_epoch())
                                        .count());
}
mcap::ByteView view(const std::vector<std::byte>& b) {
  return {reinterpret_cast<const std::uint8_t*>(b.data()), b.size()};
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
    return Error{options.path + ": " + st.message};
  }
  r->waitset_ = dds_create_waitset(participant.handle());
  for (const msgs::TopicSpec* spec : wanted) {
    const std::string ros = msgs::topic_name(*spec, options.ns);
    auto sub = Subscription::create(participant, *spec, ros, qos_for(*spec));
    if (!sub) return sub.error();
    dds_waitset_attach(r->waitset_, sub->reader(), static_cast<dds_attach_t>(r->topics_.size()));
    r->topics_.push_back(Topic{std::move(sub.value()), 0, 0, Gaps{}});
    if (spec->id == msgs::TopicId::Scene) r->scene_pending_ = true;
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
  if (auto st = writer_.write_compressed_chunk(); !st.ok()) return Error{options_.path + ": " + st.message};
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
      const bool is_scene = t.subscription.spec().id == msgs::TopicId::Scene;
      if (scene_pending_ && !is_scene) {
        held_bytes_ += sample.cdr.size();
        held_.push_back({static_cast<std::size_t>(&t - topics_.data()), std::move(sample), now});
        ++received_;
      } else {
        if (is_scene && scene_pending_) {
          scene_pending_ = false;
          const std::uint64_t log_time = held_.empty() ? now : std::min(now, held_.front().log_time);
          if (Status st = write(t, sample, log_time); !st) return st.error();
          ++received_;
          if (Status st = release_held(); !st) return st.error();
        } else {
          if (Status st = write(t, sample, now); !st) return st.error();
          ++received_;
        }
      }
      if (options_.max_messages > 0 && received_ >= options_.max_messages) return any;
    }
  }
  // No scene description after kHoldNs (or kHoldBytes held): stop waiting for it (the readers
  // find it wherever it is).
  if (scene_pending_ && !held_.empty() &&
      (wall_ns() - held_.front().log_time > kHoldNs || held_bytes_ > kHoldBytes)) {
    scene_pending_ = false;
    if (Status st = release_held(); !st) return st.error();
  }
  return any;
}

Status Recorder::write(Topic& t, const Received& sample, std::uint64_t log_time) {
  if (t.channel == 0) {  // like rosbag2: the channel says what the (first) publisher offers
    auto channel = log::add_topic(writer_, t.subscription.spec(), options_.ns, sample.offered);
    if (!channel.ok()) return Error{options_.path + ": " + channel.status().message};
    t.channel = channel.value();
  }
  const std::uint64_t source =
      sample.source_time_ns > 0 ? static_cast<std::uint64_t>(sample.source_time_ns) : log_time;
  if (auto st = writer_.write_message(t.channel, t.received, log_time, source, view(sample.cdr)); !st.ok()) {
    return Error{options_.path + ": " + st.message};
  }
  ++t.received;
  const msgs::TopicId id = t.subscription.spec().id;
  if (id == msgs::TopicId::Scene) {
    if (auto scene = msgs::decode_scene(sample.cdr); scene && scene.value().dt > 0.0) dt_ = scene.value().dt;
  } else if (const auto stamp = msgs::decode_stamp(id, sample.cdr)) {
    t.gaps.add(static_cast<std::int64_t>(stamp->sec) * 1'000'000'000 + stamp->nanosec, dt_);
  }
  return Ok{};
}

Status Recorder::release_held() {
  for (Held& h : held_) {
    if (Status st = write(topics_[h.topic], h.sample, h.log_time); !st) return st;
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
  if (auto st = writer_.close(); !st.ok()) return Error{options_.path + ": " + st.message};
  return Ok{};
}

}  // namespace rbsim::node
