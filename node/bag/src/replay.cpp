// The replay: an MCAP recording republished over DDS with its recorded timing.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <map>
#include <set>

#include "player.hpp"
#include "rbsim/clock.hpp"
#include "rbsim/recording.hpp"
#include "rbsim/replay.hpp"
#include "rbsim/service_set.hpp"

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
  std::unique_ptr<PlayerControl> control;
  ServiceSet services;   // after `control`: stopped (destroyed) before what its handlers use
  bool delayed = false;  // --delay waited (the first pass only)

  // The simulated time of a message: its own stamp (the scene description's too), else nullopt.
  std::optional<std::uint64_t> sim_time(std::uint16_t channel, std::span<const std::byte> cdr) const;
  // Publishes, per latched channel, the last message before `start`, or else the first one at or
  // after it (then in `sent_early`, not sent twice).
  Status send_latched(std::uint64_t start, std::set<std::uint16_t>& sent_early,
                      std::map<std::uint16_t, mcap::Message>& latched,
                      const std::function<void(std::uint16_t, const mcap::Message&)>& sent, bool (*stop)());
  // The log time a seek to simulated time `sim_ns` lands at: the first message of a per-step
  // channel stamped at or after it (nullopt: past the end).
  Result<std::optional<std::uint64_t>> seek_position(std::uint64_t sim_ns);
  // Where a pass starts: --start-offset seconds of log time after the first message.
  std::uint64_t start_of(std::uint64_t first_log_time) const;
  // Where a pass ends: --playback-duration (log time from `start`) and --playback-until (simulated
  // time); past both given, as rosbag2's player plays until the later of the two.
  struct End {
    std::optional<std::uint64_t> log, sim;
    bool past(std::uint64_t log_time, std::optional<std::uint64_t> sim_ns) const;
  };
  End end_of(std::uint64_t start) const;
};

Replay::~Replay() {
  // A service handler waiting for the loop is answered now; then the services stop (Impl).
  if (impl_ && impl_->control) impl_->control->close();
}

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

  im.control = std::make_unique<PlayerControl>(options.rate, options.start_paused);
  im.control->jump(r->first_log_time_);
  if (options.services) {
    if (Status added = add_player_services(im.services, participant, participant.node().fully_qualified(),
                                           *im.control, options.service_wait_s);
        !added)
      return added.error();
    im.services.start();
  }
  return r;
}

PlayerStatus Replay::status() const {
  return impl_->control->status();
}

void Replay::close_player() {
  impl_->control->close();
}

std::vector<Replay::PlayerService> Replay::player_services() const {
  std::vector<PlayerService> out;
  for (node::PlayerService& s : node::player_services(*impl_->control, impl_->options.service_wait_s)) {
    out.push_back(
        {std::move(s.name), std::move(s.type),
         [handler = std::move(s.handler)](std::span<const std::byte> request) -> std::optional<Bytes> {
           Bytes reply;
           if (!handler(RequestHeader{}, request, reply)) return std::nullopt;
           return reply;
         }});
  }
  return out;
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

std::optional<std::uint64_t> Replay::Impl::sim_time(std::uint16_t channel,
                                                    std::span<const std::byte> cdr) const {
  const msgs::TopicId id = topic_of.at(channel);
  std::optional<msgs::Time> stamp;
  if (id == msgs::TopicId::Scene) {
    // A live recording's log time is wall time, the scene's stamp is simulated.
    if (auto scene = msgs::decode_scene(cdr)) stamp = scene.value().stamp;
  } else {
    stamp = msgs::decode_stamp(id, cdr);
  }
  if (!stamp) return std::nullopt;
  return static_cast<std::uint64_t>(std::max<std::int32_t>(0, stamp->sec)) * 1'000'000'000ull +
         stamp->nanosec;
}

Status Replay::Impl::send_latched(std::uint64_t start, std::set<std::uint16_t>& sent_early,
                                  std::map<std::uint16_t, mcap::Message>& latched,
                                  const std::function<void(std::uint16_t, const mcap::Message&)>& sent,
                                  bool (*stop)()) {
  latched.clear();
  sent_early.clear();
  if (latched_channels.empty()) return Ok{};
  log::MessageFilter latched_topics;
  for (const log::RecordedChannel& c : recording->channels()) {
    if (latched_channels.count(c.channel->id) > 0) latched_topics.topics.push_back(c.channel->topic);
  }
  Status st = recording->read_messages(latched_topics, [&](const log::RecordedMessage& rm) {
    const mcap::Message& m = *rm.message;
    const std::uint16_t ch = m.channel_id;
    if (latched_channels.count(ch) == 0) return true;
    if (m.log_time < start || latched.count(ch) == 0) latched[ch] = m;
    // Past the start with one per channel: the rest of the log cannot change the choice.
    return m.log_time < start || latched.size() < latched_channels.size();
  });
  if (!st) return Error{"cannot read " + st.error().message};
  for (const auto& [ch, m] : latched) {
    if (stop()) return Ok{};
    if (Status s = publishers[route.at(ch)].publish(m.data); !s) return s.error();
    sent(ch, m);
    if (m.log_time >= start) sent_early.insert(ch);
  }
  return Ok{};
}

Result<std::optional<std::uint64_t>> Replay::Impl::seek_position(std::uint64_t sim_ns) {
  std::optional<std::uint64_t> found;
  Status st = recording->read_messages({topics}, [&](const log::RecordedMessage& rm) {
    const mcap::Message& m = *rm.message;
    const auto id = topic_of.find(m.channel_id);
    if (id == topic_of.end() || !msgs::topic(id->second).per_step) return true;
    const std::optional<std::uint64_t> t = sim_time(m.channel_id, m.data);
    if (!t || *t < sim_ns) return true;
    found = m.log_time;
    return false;
  });
  if (!st) return Error{"cannot read " + st.error().message};
  return found;
}

namespace {
std::uint64_t seconds_ns(double s) {
  return static_cast<std::uint64_t>(std::llround(std::max(0.0, s) * 1e9));
}
}  // namespace

std::uint64_t Replay::Impl::start_of(std::uint64_t first_log_time) const {
  const double offset_ns = std::max(0.0, options.start_offset) * 1e9;
  return offset_ns >= static_cast<double>(mcap::kMaxTime - first_log_time)
             ? mcap::kMaxTime
             : first_log_time + static_cast<std::uint64_t>(std::llround(offset_ns));
}

Replay::Impl::End Replay::Impl::end_of(std::uint64_t start) const {
  End e;
  if (options.playback_duration) e.log = start + seconds_ns(*options.playback_duration);
  if (options.playback_until) e.sim = seconds_ns(*options.playback_until);
  return e;
}

bool Replay::Impl::End::past(std::uint64_t log_time, std::optional<std::uint64_t> sim_ns) const {
  if (!log && !sim) return false;
  const bool log_past = !log || log_time > *log;
  const bool sim_past = !sim || (sim_ns && *sim_ns > *sim);
  return log_past && sim_past;
}

Result<bool> Replay::play(bool (*stop)(), const Tap* tap) {
  Impl& im = *impl_;
  PlayerControl& control = *im.control;
  if (tap != nullptr && tap->pass) tap->pass();
  if (!im.delayed && im.options.delay > 0.0) {
    im.delayed = true;
    if (!sleep_until_or_stop(monotonic_ns() + static_cast<std::int64_t>(std::llround(im.options.delay * 1e9)),
                             stop))
      return false;
  }
  // The simulated time of a message for the tap: its own stamp, else the last one seen (the scene
  // description carries none the tap needs), else its log time.
  std::optional<std::uint64_t> last_sim;
  auto to_tap = [&](std::uint16_t channel, std::uint64_t log_time, std::span<const std::byte> cdr,
                    std::optional<std::uint64_t> sim) {
    if (tap == nullptr || !tap->message) return;
    tap->message(im.output_of.at(channel), sim.value_or(last_sim.value_or(log_time)), cdr);
  };
  auto publish_clock = [&](std::uint64_t t) -> Status {
    const auto cdr = clock_cdr(t);
    if (Status s = im.publishers[*im.clock_publisher].publish(cdr); !s) return s;
    if (tap != nullptr && tap->message) tap->message(outputs_.size() - 1, t, cdr);
    ++published_;
    return Ok{};
  };
  const std::uint64_t start = im.start_of(first_log_time_);
  const Impl::End end = im.end_of(start);
  std::map<std::uint16_t, mcap::Message> latched;
  std::set<std::uint16_t> sent_early;
  auto latched_sent = [&](std::uint16_t ch, const mcap::Message& m) {
    const std::optional<std::uint64_t> sim = im.sim_time(ch, m.data);
    to_tap(ch, m.log_time, m.data, sim);
    if (sim && im.topic_of.at(ch) != msgs::TopicId::Scene) last_sim = sim;
    ++published_;
  };
  // Where reading resumes: a log time and how many messages at that log time were already seen
  // (after a refused seek, the read restarts where it stopped).
  std::uint64_t from = start;
  std::uint64_t skip_at_from = 0;
  bool fresh = true;  // a new segment: latched topics first, the clock starts at its first message
  std::optional<Error> failure;
  std::optional<std::uint64_t> last_clock;
  while (true) {
    if (fresh) {
      if (Status st = im.send_latched(from, sent_early, latched, latched_sent, stop); !st) return st.error();
      if (stop()) break;
    }
    bool started = !fresh;
    bool stopped = false, interrupted = false;
    std::uint64_t seen_at = 0, seen_count = 0;  // the current log time, messages seen at it
    std::uint64_t skip = skip_at_from;
    log::MessageFilter played{im.topics, from};
    Status st = im.recording->read_messages(played, [&](const log::RecordedMessage& rm) {
      const mcap::Message& m = *rm.message;
      if (m.log_time != seen_at) {
        seen_at = m.log_time;
        seen_count = 0;
      }
      if (m.log_time == from && skip > 0) {
        --skip;
        ++seen_count;
        return true;
      }
      const auto route = im.route.find(m.channel_id);
      if (route == im.route.end()) {  // a channel of the same name we do not replay
        ++seen_count;
        return true;
      }
      if (sent_early.count(m.channel_id) > 0 && latched.at(m.channel_id).log_time == m.log_time &&
          latched.at(m.channel_id).sequence == m.sequence) {
        sent_early.erase(m.channel_id);
        ++seen_count;
        return true;
      }
      const std::optional<std::uint64_t> sim = im.sim_time(m.channel_id, m.data);
      if (end.past(m.log_time, sim.has_value() ? sim : last_sim)) return false;
      if (!started) {
        started = true;
        control.jump(m.log_time);
      }
      switch (control.wait_due(m.log_time, stop)) {
        case PlayerControl::Next::Stop:
          stopped = true;
          return false;
        case PlayerControl::Next::Seek:
          interrupted = true;
          from = m.log_time;
          skip_at_from = seen_count;
          return false;
        case PlayerControl::Next::Publish:
          break;
      }
      ++seen_count;
      if (im.clock_publisher && last_clock != m.log_time) {
        if (Status s = publish_clock(m.log_time); !s) {
          failure = s.error();
          return false;
        }
        last_clock = m.log_time;
      }
      if (Status s = im.publishers[route->second].publish(m.data); !s) {
        failure = s.error();
        return false;
      }
      const bool per_step = msgs::topic(im.topic_of.at(m.channel_id)).per_step;
      to_tap(m.channel_id, m.log_time, m.data, sim);
      if (sim && im.topic_of.at(m.channel_id) != msgs::TopicId::Scene) last_sim = sim;
      ++published_;
      control.published(m.log_time, per_step ? sim : std::nullopt);
      return true;
    });
    if (!st) return Error{"cannot read " + st.error().message};
    if (failure) return *failure;
    if (stopped) {
      control.pass_end();
      return false;
    }
    if (!interrupted) break;
    // A seek: to the first per-step message at or after the simulated time asked for (the start of
    // the log for a time before it); refused past the end, where playing goes on undisturbed.
    const std::optional<std::uint64_t> target = control.take_seek();
    if (!target) {
      fresh = false;
      continue;
    }
    auto position = im.seek_position(*target);
    if (!position) return position.error();
    if (!position.value()) {
      control.seek_done(false, 0);
      fresh = false;
      continue;
    }
    from = *position.value();
    skip_at_from = 0;
    fresh = true;
    if (tap != nullptr && tap->pass) tap->pass();  // a second output starts afresh there too
    if (im.clock_publisher) {
      if (Status s = publish_clock(from); !s) return s.error();
      last_clock = from;
    }
    control.seek_done(true, from);
  }
  control.pass_end();
  return !stop();
}

}  // namespace rbsim::node
