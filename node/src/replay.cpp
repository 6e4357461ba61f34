// The replay: an MCAP recording republished over DDS with its recorded timing.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <map>
#include <set>

#include "clock.hpp"
#include "rbsim/recording.hpp"
#include "rbsim/replay.hpp"

namespace rbsim::node {

namespace {
// Sleeps until `deadline_ns` (monotonic) in slices of at most 50 ms, so a stop request is seen
// promptly whichever thread the signal went to; false when `stop` turned true.
bool sleep_until_or_stop(std::int64_t deadline_ns, bool (*stop)()) {
  constexpr std::int64_t kSlice = 50'000'000;
  while (true) {
    if (stop()) return false;
    const std::int64_t now = monotonic_ns();
    if (now >= deadline_ns) return true;
    sleep_until(std::min(deadline_ns, now + kSlice));
  }
}

// rosgraph_msgs/msg/Clock in CDR: encapsulation header (CDR_LE), int32 sec, uint32 nanosec.
std::array<std::byte, 12> clock_cdr(std::uint64_t t_ns) {
  std::array<std::byte, 12> out{};
  out[1] = std::byte{1};
  const auto sec = static_cast<std::int32_t>(t_ns / 1'000'000'000);
  const auto nsec = static_cast<std::uint32_t>(t_ns % 1'000'000'000);
  std::memcpy(out.data() + 4, &sec, 4);
  std::memcpy(out.data() + 8, &nsec, 4);
  return out;
}
}  // namespace

struct Replay::Impl {
  ReplayOptions options;
  std::unique_ptr<log::Recording> recording;
  std::vector<Publisher> publishers;
  std::map<std::uint16_t, std::size_t> route;       // replayed channel id -> publisher index
  std::set<std::uint16_t> latched_channels;         // replayed channels of latched topics (scene, markers)
  std::map<std::uint16_t, std::size_t> output_of;   // replayed channel id -> index in outputs_
  std::map<std::uint16_t, msgs::TopicId> topic_of;  // replayed channel id -> its topic's id
  std::vector<std::string> topics;                  // replayed channel topics (the read filter)
  std::optional<std::size_t> clock_publisher;
  std::size_t wait_publisher = 0;
};

Replay::~Replay() = default;

Result<std::unique_ptr<Replay>> Replay::open(const Participant& participant, const ReplayOptions& options) {
  std::unique_ptr<Replay> r(new Replay());
  r->impl_ = std::make_unique<Impl>();
  Impl& im = *r->impl_;
  im.options = options;
  const std::string& path = options.path;
  // Raw messages only: every channel of our types is replayed as recorded, whatever it holds.
  auto opened = log::Recording::open(path, log::raw_options());
  if (!opened) return Error{"cannot read " + opened.error().message};
  im.recording = std::move(opened.value());

  // Channels that carry one of our types as CDR (found by type), by id (file order).
  using Candidate = const log::RecordedChannel*;
  std::vector<Candidate> candidates;
  for (const log::RecordedChannel& c : im.recording->channels()) {
    if (c.spec == nullptr) continue;
    if (!c.problem.empty()) {
      r->warnings_.push_back("skipping " + c.channel->topic + ": " + c.problem);
      continue;
    }
    candidates.push_back(&c);
  }
  if (candidates.empty()) {
    std::string why = "none of its channels carries an rbsim message type as CDR";
    for (const std::string& w : r->warnings_) why += "; " + w;
    return Error{path + ": no rbsim topics in this log (" + why + ")"};
  }

  // --topics: every name must pick at least one recorded rbsim channel.
  if (!options.topics.empty()) {
    std::vector<Candidate> chosen;
    for (const std::string& name : options.topics) {
      bool found = false;
      for (const Candidate c : candidates) {
        if (msgs::names_topic(name, c->channel->topic) || name == c->spec->suffix) {
          found = true;
          if (std::none_of(chosen.begin(), chosen.end(), [&](const Candidate x) { return x == c; })) {
            chosen.push_back(c);
          }
        }
      }
      if (!found) {
        std::string known;
        for (const Candidate c : candidates) known += (known.empty() ? "" : ", ") + c->channel->topic;
        return Error{"unknown topic \"" + name + "\": " + path + " has " + known};
      }
    }
    std::sort(chosen.begin(), chosen.end(),
              [](const Candidate a, const Candidate b) { return a->channel->id < b->channel->id; });
    candidates = std::move(chosen);
  }
  if (options.clock) {
    std::erase_if(candidates, [](const Candidate c) { return c->spec->id == msgs::TopicId::Clock; });
    if (candidates.empty())
      return Error{"nothing to replay: --topics selects only /clock, which --clock replaces"};
  }

  // One publisher per published topic name (channels that map onto the same name share it).
  std::map<std::string, std::pair<std::size_t, const msgs::TopicSpec*>> by_topic;
  auto publisher_for = [&](const msgs::TopicSpec& spec, const std::string& topic) -> Result<std::size_t> {
    if (auto it = by_topic.find(topic); it != by_topic.end()) {
      if (it->second.second != &spec) {
        return Error{"cannot publish " + std::string(spec.type) + " and " +
                     std::string(it->second.second->type) + " on the same topic " + topic};
      }
      return it->second.first;
    }
    auto pub = Publisher::create(participant, spec, topic, qos_for(spec, options.keep_last));
    if (!pub) return pub.error();
    im.publishers.push_back(std::move(pub.value()));
    by_topic.emplace(topic, std::make_pair(im.publishers.size() - 1, &spec));
    return im.publishers.size() - 1;
  };
  std::optional<std::size_t> states_publisher;
  for (const Candidate c : candidates) {
    const std::string topic = options.ns ? msgs::topic_name(*c->spec, *options.ns) : c->channel->topic;
    auto index = publisher_for(*c->spec, topic);
    if (!index) return index.error();
    im.route.emplace(c->channel->id, index.value());
    if (c->spec->latched()) im.latched_channels.insert(c->channel->id);
    if (c->spec->id == msgs::TopicId::BodyStates && !states_publisher) states_publisher = index.value();
    im.topics.push_back(c->channel->topic);
    im.output_of.emplace(c->channel->id, r->outputs_.size());
    im.topic_of.emplace(c->channel->id, c->spec->id);
    r->outputs_.push_back({c->channel->topic, topic, c->message_count.value_or(0), std::string(c->spec->type),
                           std::string(c->schema_text()), c->spec->latched()});
  }
  if (options.clock) {
    const msgs::TopicSpec& spec = msgs::topic(msgs::TopicId::Clock);
    auto index = publisher_for(spec, msgs::topic_name(spec, ""));
    if (!index) return index.error();
    im.clock_publisher = index.value();
    auto schema = msgs::ros2msg_schema(spec.type);
    if (!schema) return schema.error();
    r->outputs_.push_back(
        {"", msgs::topic_name(spec, ""), 0, std::string(spec.type), std::move(schema.value()), false});
  }
  im.wait_publisher = states_publisher.value_or(0);

  // The log-time range of the replayed channels: the first message is where pacing and
  // --start-offset count from.
  bool any = false;
  Status st = im.recording->read_messages({im.topics}, [&](const log::RecordedMessage& m) {
    r->first_log_time_ = m.message->log_time;
    any = true;
    return false;
  });
  if (!st) return Error{"cannot read " + st.error().message};
  if (!any) return Error{path + ": the log has rbsim topics but no messages on them"};
  r->last_log_time_ = std::max(r->first_log_time_, im.recording->last_log_time().value_or(0));
  return r;
}

bool Replay::wait_for_subscribers(std::int32_t count, bool (*stop)()) {
  const Publisher& pub = impl_->publishers[impl_->wait_publisher];
  while (pub.matched() < count) {
    if (!sleep_until_or_stop(monotonic_ns() + 20'000'000, stop)) return false;
  }
  return true;
}

Status Replay::finish(double timeout_s) {
  for (Publisher& p : impl_->publishers) {
    if (Status st = p.flush(timeout_s); !st) return st;
  }
  return Ok{};
}

Result<bool> Replay::play(bool (*stop)(), const Tap* tap) {
  Impl& im = *impl_;
  if (tap != nullptr && tap->pass) tap->pass();
  // The simulated time of a message for the tap: its own stamp, else the last one seen (the scene
  // description carries none the tap needs), else its log time.
  std::optional<std::uint64_t> last_sim;
  auto to_tap = [&](std::uint16_t channel, std::uint64_t log_time, std::span<const std::byte> cdr) {
    if (tap == nullptr || !tap->message) return;
    std::uint64_t t = last_sim.value_or(log_time);
    const msgs::TopicId id = im.topic_of.at(channel);
    std::optional<msgs::Time> stamp;
    if (id == msgs::TopicId::Scene) {
      // Once per pass: a live recording's log time is wall time, the scene's stamp is simulated.
      if (auto scene = msgs::decode_scene(cdr)) stamp = scene.value().stamp;
    } else {
      stamp = msgs::decode_stamp(id, cdr);
    }
    if (stamp) {
      t = static_cast<std::uint64_t>(std::max<std::int32_t>(0, stamp->sec)) * 1'000'000'000ull +
          stamp->nanosec;
      if (id != msgs::TopicId::Scene) last_sim = t;
    }
    tap->message(im.output_of.at(channel), t, cdr);
  };
  const double offset_ns = std::max(0.0, im.options.start_offset) * 1e9;
  const std::uint64_t start = offset_ns >= static_cast<double>(mcap::kMaxTime - first_log_time_)
                                  ? mcap::kMaxTime
                                  : first_log_time_ + static_cast<std::uint64_t>(std::llround(offset_ns));

  // The latched topics (scene description, markers) go first: per latched channel, the last
  // message before the start, or else the first one of the played part (then not sent twice).
  std::map<std::uint16_t, mcap::Message> latched;
  std::set<std::uint16_t> sent_early;
  if (!im.latched_channels.empty()) {
    log::MessageFilter latched_topics;
    for (const log::RecordedChannel& c : im.recording->channels()) {
      if (im.latched_channels.count(c.channel->id) > 0) latched_topics.topics.push_back(c.channel->topic);
    }
    Status st = im.recording->read_messages(latched_topics, [&](const log::RecordedMessage& rm) {
      const mcap::Message& m = *rm.message;
      const std::uint16_t ch = m.channel_id;
      if (im.latched_channels.count(ch) == 0) return true;
      if (m.log_time < start || latched.count(ch) == 0) latched[ch] = m;
      // Past the start with one per channel: the rest of the log cannot change the choice.
      return m.log_time < start || latched.size() < im.latched_channels.size();
    });
    if (!st) return Error{"cannot read " + st.error().message};
    for (const auto& [ch, m] : latched) {
      if (stop()) return false;
      if (Status s = im.publishers[im.route.at(ch)].publish(m.data); !s) return s.error();
      to_tap(ch, m.log_time, m.data);
      ++published_;
      if (m.log_time >= start) sent_early.insert(ch);
    }
  }

  std::optional<Error> failure;
  bool stopped = false;
  bool started = false;
  std::int64_t wall0 = 0;
  std::uint64_t t0 = 0;
  std::optional<std::uint64_t> last_clock;
  const double rate = im.options.rate;
  log::MessageFilter played{im.topics, start};
  Status st = im.recording->read_messages(played, [&](const log::RecordedMessage& rm) {
    const mcap::Message& m = *rm.message;
    const auto route = im.route.find(m.channel_id);
    if (route == im.route.end()) return true;  // a channel of the same name we do not replay
    if (sent_early.count(m.channel_id) > 0 && latched.at(m.channel_id).log_time == m.log_time &&
        latched.at(m.channel_id).sequence == m.sequence) {
      sent_early.erase(m.channel_id);
      return true;
    }
    if (!started) {
      started = true;
      wall0 = monotonic_ns();
      t0 = m.log_time;
    }
    if (rate > 0.0) {
      const double due = static_cast<double>(m.log_time - t0) / rate;
      if (!sleep_until_or_stop(wall0 + static_cast<std::int64_t>(std::llround(due)), stop)) {
        stopped = true;
        return false;
      }
    } else if (stop()) {
      stopped = true;
      return false;
    }
    if (im.clock_publisher && last_clock != m.log_time) {
      const auto cdr = clock_cdr(m.log_time);
      if (Status s = im.publishers[*im.clock_publisher].publish(cdr); !s) {
        failure = s.error();
        return false;
      }
      last_clock = m.log_time;
      if (tap != nullptr && tap->message) tap->message(outputs_.size() - 1, m.log_time, cdr);
      ++published_;
    }
    if (Status s = im.publishers[route->second].publish(m.data); !s) {
      failure = s.error();
      return false;
    }
    to_tap(m.channel_id, m.log_time, m.data);
    ++published_;
    return true;
  });
  if (!st) return Error{"cannot read " + st.error().message};
  if (failure) return *failure;
  return !stopped;
}

}  // namespace rbsim::node
