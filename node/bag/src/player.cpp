// The replay: an MCAP recording republished over DDS with its recorded timing.
#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "player_clock.hpp"
#include "rbsim/clock.hpp"
#include "rbsim/player.hpp"
#include "rbsim/recording.hpp"
#include "rbsim/service_set.hpp"

namespace rbsim::bag {

using namespace node;

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
}  // namespace

struct Player::Impl {
  PlayOptions options;
  std::unique_ptr<recordings::Recording> recording;
  std::vector<Publisher> publishers;
  std::map<std::uint16_t, std::size_t> route;       // replayed channel id -> publisher index
  std::set<std::uint16_t> latched_channels;         // replayed channels of latched topics (scene, markers)
  std::map<std::uint16_t, std::size_t> output_of;   // replayed channel id -> index in outputs_
  std::map<std::uint16_t, msgs::TopicId> topic_of;  // replayed channel id -> its topic's id
  std::vector<std::string> topics;                  // replayed channel topics (the read filter)
  std::optional<std::size_t> clock_publisher;
  std::size_t wait_publisher = 0;
  std::unique_ptr<PlayerClock> control;
  ServiceSet services;   // after `control`: stopped (destroyed) before what its handlers use
  bool delayed = false;  // --delay waited (the first pass only)

  // The simulated time of a message: its own stamp (the scene description's too), else nullopt.
  std::optional<std::uint64_t> sim_time(std::uint16_t channel, std::span<const std::byte> cdr) const;
  // Publishes, per latched channel, the last message before `start`, or else the first one at or
  // after it (then in `sent_early`, not sent twice).
  Status send_latched(std::uint64_t start, std::set<std::uint16_t>& sent_early,
                      std::map<std::uint16_t, mcap::Message>& latched,
                      const std::function<void(std::uint16_t, const mcap::Message&)>& sent, bool (*stop)());
  // Where playing goes on from log time `from` (a pass's start) or to simulated time `sim_ns` (a
  // seek): the first message of a per-step channel at or after `from` stamped at or after
  // `sim_ns`, its log time and simulated time (nullopt: past the end).
  struct StepAt {
    std::uint64_t log_time = 0, sim_time = 0;
  };
  Result<std::optional<StepAt>> first_step(std::uint64_t from, std::uint64_t sim_ns);
  // Where a pass starts: --start-offset seconds of log time after the first message.
  std::uint64_t start_of(std::uint64_t first_log_time) const;
  // Where a pass ends: --playback-duration (log time from `start`) and --playback-until (simulated
  // time); past both given, as rosbag2's player plays until the later of the two.
  struct End {
    std::optional<std::uint64_t> log, sim;
    bool past(std::uint64_t log_time, std::optional<std::uint64_t> sim_ns) const;
  };
  End end_of(std::uint64_t start) const;

  // open()'s stages, in order.
  using Candidate = const recordings::RecordedChannel*;
  // The channels that carry one of our types as CDR (found by type), by id (file order); those
  // that cannot be read are skipped with a warning.
  Result<std::vector<Candidate>> candidates(std::vector<std::string>& warnings) const;
  // --topics and --clock narrow the candidates down.
  Result<std::vector<Candidate>> choose(std::vector<Candidate> candidates) const;
  // A publisher per published topic name, the routes to them, and the outputs listed.
  Status create_publishers(const Participant& participant, const std::vector<Candidate>& candidates,
                           std::vector<Output>& outputs);
  // The log-time range of the replayed channels.
  Status find_span(Player& r) const;
  // The player's control at the first message, and its services.
  Status start_control(const Participant& participant, std::uint64_t first_log_time);

  // One call of play(): the segments it reads (from its start, then from each seek), and what
  // they leave for the next.
  struct Pass;
};

Player::~Player() {
  // A service handler waiting for the loop is answered now; then the services stop (Impl).
  if (impl_ && impl_->control) impl_->control->close();
}

Result<std::unique_ptr<Player>> Player::open(const Participant& participant, const PlayOptions& options) {
  std::unique_ptr<Player> r(new Player());
  r->impl_ = std::make_unique<Impl>();
  Impl& im = *r->impl_;
  im.options = options;
  const std::string& path = options.path;
  // Raw messages only: every channel of our types is replayed as recorded, whatever it holds.
  auto opened = recordings::Recording::open(path, recordings::raw_options());
  if (!opened) return with_context("cannot read ", opened.error());
  im.recording = std::move(opened.value());

  auto candidates = im.candidates(r->warnings_);
  if (!candidates) return candidates.error();
  auto chosen = im.choose(std::move(candidates.value()));
  if (!chosen) return chosen.error();
  if (Status st = im.create_publishers(participant, chosen.value(), r->outputs_); !st) return st.error();
  if (Status st = im.find_span(*r); !st) return st.error();
  if (Status st = im.start_control(participant, r->first_log_time_); !st) return st.error();
  return r;
}

Result<std::vector<Player::Impl::Candidate>> Player::Impl::candidates(
    std::vector<std::string>& warnings) const {
  const std::string& path = options.path;
  std::vector<Candidate> candidates;
  for (const recordings::RecordedChannel& c : recording->channels()) {
    if (c.spec == nullptr) continue;
    if (!c.problem.empty()) {
      warnings.push_back("skipping " + c.channel->topic + ": " + c.problem);
      continue;
    }
    candidates.push_back(&c);
  }
  if (candidates.empty()) {
    std::string why = "none of its channels carries an rbsim message type as CDR";
    for (const std::string& w : warnings) why += "; " + w;
    return Error{path + ": no rbsim topics in this log (" + why + ")"};
  }
  return candidates;
}

Result<std::vector<Player::Impl::Candidate>> Player::Impl::choose(std::vector<Candidate> candidates) const {
  const std::string& path = options.path;
  // --topics: every name must pick at least one recorded rbsim channel (msgs::select_topics()).
  if (!options.topics.empty()) {
    std::vector<msgs::TopicCandidate> named;
    for (const Candidate c : candidates) named.push_back({c->channel->topic, c->spec});
    msgs::TopicFilter filter;
    filter.topics = options.topics;
    Result<std::vector<std::size_t>> chosen = msgs::select_topics(filter, named);
    if (!chosen) return Error{path + ": " + chosen.error().message};
    std::vector<Candidate> kept;
    for (const std::size_t i : chosen.value()) kept.push_back(candidates[i]);
    std::sort(kept.begin(), kept.end(),
              [](const Candidate a, const Candidate b) { return a->channel->id < b->channel->id; });
    candidates = std::move(kept);
  }
  if (options.clock) {
    std::erase_if(candidates, [](const Candidate c) { return c->spec->id == msgs::TopicId::Clock; });
    if (candidates.empty())
      return Error{"nothing to replay: --topics selects only /clock, which --clock replaces"};
  }
  return candidates;
}

Status Player::Impl::create_publishers(const Participant& participant,
                                       const std::vector<Candidate>& candidates,
                                       std::vector<Output>& outputs) {
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
    publishers.push_back(std::move(pub.value()));
    by_topic.emplace(topic, std::make_pair(publishers.size() - 1, &spec));
    return publishers.size() - 1;
  };
  std::optional<std::size_t> states_publisher;
  for (const Candidate c : candidates) {
    const std::string topic = options.ns ? msgs::topic_name(*c->spec, *options.ns) : c->channel->topic;
    auto index = publisher_for(*c->spec, topic);
    if (!index) return index.error();
    route.emplace(c->channel->id, index.value());
    if (c->spec->latched()) latched_channels.insert(c->channel->id);
    if (c->spec->id == msgs::TopicId::BodyStates && !states_publisher) states_publisher = index.value();
    topics.push_back(c->channel->topic);
    output_of.emplace(c->channel->id, outputs.size());
    topic_of.emplace(c->channel->id, c->spec->id);
    outputs.push_back({c->channel->topic, topic, c->message_count.value_or(0), std::string(c->spec->type),
                       std::string(c->schema_text()), c->spec->latched()});
  }
  if (options.clock) {
    const msgs::TopicSpec& spec = msgs::topic(msgs::TopicId::Clock);
    auto index = publisher_for(spec, msgs::topic_name(spec, ""));
    if (!index) return index.error();
    clock_publisher = index.value();
    auto schema = msgs::ros2msg_schema(spec.type);
    if (!schema) return schema.error();
    outputs.push_back(
        {"", msgs::topic_name(spec, ""), 0, std::string(spec.type), std::move(schema.value()), false});
  }
  wait_publisher = states_publisher.value_or(0);
  return Ok{};
}

Status Player::Impl::find_span(Player& r) const {
  const std::string& path = options.path;
  // The first message is where pacing and --start-offset count from.
  bool any = false;
  Status st = recording->read_messages({topics}, [&](const recordings::RecordedMessage& m) {
    r.first_log_time_ = m.message->log_time;
    any = true;
    return false;
  });
  if (!st) return with_context("cannot read ", st.error());
  if (!any) return Error{path + ": the log has rbsim topics but no messages on them"};
  r.last_log_time_ = std::max(r.first_log_time_, recording->last_log_time().value_or(0));
  return Ok{};
}

Status Player::Impl::start_control(const Participant& participant, std::uint64_t first_log_time) {
  control = std::make_unique<PlayerClock>(options.rate, options.start_paused);
  control->jump(first_log_time);
  if (options.services) {
    if (Status added = add_player_services(services, participant, participant.node().fully_qualified(),
                                           *control, options.service_wait_s);
        !added)
      return added.error();
    services.start();
  }
  return Ok{};
}

PlayerStatus Player::status() const {
  return impl_->control->status();
}

void Player::close_player() {
  impl_->control->close();
}

std::vector<Player::PlayerService> Player::player_services() const {
  std::vector<PlayerService> out;
  for (bag::PlayerService& s : bag::player_services(*impl_->control, impl_->options.service_wait_s)) {
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

bool Player::wait_for_subscribers(std::int32_t count, bool (*stop)()) {
  return impl_->publishers[impl_->wait_publisher].wait_for_subscribers(count, stop);
}

Status Player::finish(double timeout_s) {
  for (Publisher& p : impl_->publishers) {
    if (Status st = p.flush(timeout_s); !st) return st;
  }
  return Ok{};
}

std::optional<std::uint64_t> Player::Impl::sim_time(std::uint16_t channel,
                                                    std::span<const std::byte> cdr) const {
  const msgs::TopicId id = topic_of.at(channel);
  std::optional<msgs::Time> stamp;
  if (id == msgs::TopicId::SceneDescription) {
    // A live recording's log time is wall time, the scene's stamp is simulated.
    if (auto scene = msgs::decode_scene(cdr)) stamp = scene.value().stamp;
  } else {
    stamp = msgs::decode_stamp(id, cdr);
  }
  if (!stamp) return std::nullopt;
  return static_cast<std::uint64_t>(std::max<std::int32_t>(0, stamp->sec)) * 1'000'000'000ull +
         stamp->nanosec;
}

Status Player::Impl::send_latched(std::uint64_t start, std::set<std::uint16_t>& sent_early,
                                  std::map<std::uint16_t, mcap::Message>& latched,
                                  const std::function<void(std::uint16_t, const mcap::Message&)>& sent,
                                  bool (*stop)()) {
  latched.clear();
  sent_early.clear();
  if (latched_channels.empty()) return Ok{};
  recordings::MessageFilter latched_topics;
  for (const recordings::RecordedChannel& c : recording->channels()) {
    if (latched_channels.count(c.channel->id) > 0) latched_topics.topics.push_back(c.channel->topic);
  }
  Status st = recording->read_messages(latched_topics, [&](const recordings::RecordedMessage& rm) {
    const mcap::Message& m = *rm.message;
    const std::uint16_t ch = m.channel_id;
    if (latched_channels.count(ch) == 0) return true;
    if (m.log_time < start || latched.count(ch) == 0) latched[ch] = m;
    // Past the start with one per channel: the rest of the log cannot change the choice.
    return m.log_time < start || latched.size() < latched_channels.size();
  });
  if (!st) return with_context("cannot read ", st.error());
  for (const auto& [ch, m] : latched) {
    if (stop()) return Ok{};
    if (Status s = publishers[route.at(ch)].publish(m.data); !s) return s.error();
    sent(ch, m);
    if (m.log_time >= start) sent_early.insert(ch);
  }
  return Ok{};
}

Result<std::optional<Player::Impl::StepAt>> Player::Impl::first_step(std::uint64_t from,
                                                                     std::uint64_t sim_ns) {
  std::optional<StepAt> found;
  Status st = recording->read_messages({topics, from}, [&](const recordings::RecordedMessage& rm) {
    const mcap::Message& m = *rm.message;
    const auto id = topic_of.find(m.channel_id);
    if (id == topic_of.end() || !msgs::topic(id->second).per_step) return true;
    const std::optional<std::uint64_t> t = sim_time(m.channel_id, m.data);
    if (!t || *t < sim_ns) return true;
    found = StepAt{m.log_time, *t};
    return false;
  });
  if (!st) return with_context("cannot read ", st.error());
  return found;
}

namespace {
std::uint64_t seconds_ns(double s) {
  return static_cast<std::uint64_t>(seconds_to_ns_clamped(s));
}
}  // namespace

std::uint64_t Player::Impl::start_of(std::uint64_t first_log_time) const {
  const std::uint64_t offset_ns = seconds_ns(options.start_offset);
  return offset_ns >= mcap::kMaxTime - first_log_time ? mcap::kMaxTime : first_log_time + offset_ns;
}

Player::Impl::End Player::Impl::end_of(std::uint64_t start) const {
  End e;
  if (options.playback_duration) e.log = start + seconds_ns(*options.playback_duration);
  if (options.playback_until) e.sim = seconds_ns(*options.playback_until);
  return e;
}

bool Player::Impl::End::past(std::uint64_t log_time, std::optional<std::uint64_t> sim_ns) const {
  if (!log && !sim) return false;
  const bool log_past = !log || log_time > *log;
  const bool sim_past = !sim || (sim_ns && *sim_ns > *sim);
  return log_past && sim_past;
}

struct Player::Impl::Pass {
  Pass(Player& replay, Impl& impl, bool (*stop_fn)(), const Tap* tap_to, std::uint64_t start)
      : r(replay),
        im(impl),
        control(*impl.control),
        stop(stop_fn),
        tap(tap_to),
        end(impl.end_of(start)),
        from(start) {}

  Player& r;
  Impl& im;
  PlayerClock& control;
  bool (*stop)();
  const Tap* tap;
  const End end;
  // The simulated time of a message for the tap: its own stamp, else the last one seen (the scene
  // description carries none the tap needs), else its log time.
  std::optional<std::uint64_t> last_sim;
  std::map<std::uint16_t, mcap::Message> latched;
  std::set<std::uint16_t> sent_early;
  // Where reading resumes: a log time and how many messages at that log time were already seen
  // (after a refused seek, the read restarts where it stopped).
  std::uint64_t from;
  std::uint64_t skip_at_from = 0;
  bool fresh = true;  // a new segment: latched topics first, the clock starts at its first message
  std::optional<Error> failure;
  std::optional<std::uint64_t> last_clock;
  // The segment being read.
  bool started = false;
  bool stopped = false, interrupted = false;
  std::uint64_t seen_at = 0, seen_count = 0;  // the current log time, messages seen at it
  std::uint64_t skip = 0;

  void to_tap(std::uint16_t channel, std::uint64_t log_time, std::span<const std::byte> cdr,
              std::optional<std::uint64_t> sim) {
    if (tap == nullptr || !tap->message) return;
    tap->message(im.output_of.at(channel), sim.value_or(last_sim.value_or(log_time)), cdr);
  }
  msgs::Bytes cdr_of_clock;
  Status publish_clock(std::uint64_t t) {
    const msgs::Bytes& cdr = msgs::encode_clock(t, cdr_of_clock);
    if (Status s = im.publishers[*im.clock_publisher].publish(cdr); !s) return s;
    if (tap != nullptr && tap->message) tap->message(r.outputs_.size() - 1, t, cdr);
    ++r.published_;
    return Ok{};
  }
  void latched_sent(std::uint16_t ch, const mcap::Message& m) {
    const std::optional<std::uint64_t> sim = im.sim_time(ch, m.data);
    to_tap(ch, m.log_time, m.data, sim);
    if (sim && im.topic_of.at(ch) != msgs::TopicId::SceneDescription) last_sim = sim;
    ++r.published_;
  }
  // Reads from `from` to the end, a stop (`stopped`) or a seek asked for (`interrupted`).
  Status read_segment();
  // One message of the segment, paced and published; false ends the read.
  bool play_message(const recordings::RecordedMessage& rm);
  // After `interrupted`: the seek carried out, or refused.
  Status seek();
};

Status Player::Impl::Pass::read_segment() {
  started = !fresh;
  stopped = false;
  interrupted = false;
  seen_at = 0;
  seen_count = 0;
  skip = skip_at_from;
  recordings::MessageFilter played{im.topics, from};
  return im.recording->read_messages(
      played, [this](const recordings::RecordedMessage& rm) { return play_message(rm); });
}

bool Player::Impl::Pass::play_message(const recordings::RecordedMessage& rm) {
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
    case PlayerClock::Next::Stop:
      stopped = true;
      return false;
    case PlayerClock::Next::Seek:
      interrupted = true;
      from = m.log_time;
      skip_at_from = seen_count;
      return false;
    case PlayerClock::Next::Publish:
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
  if (sim && im.topic_of.at(m.channel_id) != msgs::TopicId::SceneDescription) last_sim = sim;
  ++r.published_;
  control.published(m.log_time, per_step ? sim : std::nullopt);
  return true;
}

Status Player::Impl::Pass::seek() {
  // To the first per-step message at or after the simulated time asked for (the start of the log
  // for a time before it); refused past the end, where playing goes on undisturbed.
  const std::optional<std::uint64_t> target = control.take_seek();
  if (!target) {
    fresh = false;
    return Ok{};
  }
  auto position = im.first_step(0, *target);
  if (!position) return position.error();
  if (!position.value()) {
    control.seek_done(false, 0);
    fresh = false;
    return Ok{};
  }
  from = position.value()->log_time;
  skip_at_from = 0;
  fresh = true;
  if (tap != nullptr && tap->pass)
    tap->pass(position.value()->sim_time);  // a second output starts afresh there too
  if (im.clock_publisher) {
    if (Status s = publish_clock(from); !s) return s.error();
    last_clock = from;
  }
  control.seek_done(true, from);
  return Ok{};
}

Result<bool> Player::play(bool (*stop)(), const Tap* tap) {
  Impl& im = *impl_;
  PlayerClock& control = *im.control;
  const std::uint64_t start = im.start_of(first_log_time_);
  if (tap != nullptr && tap->pass) {
    auto at = im.first_step(start, 0);
    if (!at) return at.error();
    tap->pass(at.value() ? std::optional(at.value()->sim_time) : std::nullopt);
  }
  if (!im.delayed && im.options.delay > 0.0) {
    im.delayed = true;
    if (!sleep_until_or_stop(monotonic_ns() + seconds_to_ns_clamped(im.options.delay), stop)) return false;
  }
  Impl::Pass pass(*this, im, stop, tap, start);
  const auto latched_sent = [&pass](std::uint16_t ch, const mcap::Message& m) { pass.latched_sent(ch, m); };
  while (true) {
    if (pass.fresh) {
      if (Status st = im.send_latched(pass.from, pass.sent_early, pass.latched, latched_sent, stop); !st)
        return st.error();
      if (stop()) break;
    }
    if (Status st = pass.read_segment(); !st) return with_context("cannot read ", st.error());
    if (pass.failure) return *pass.failure;
    if (pass.stopped) {
      control.pass_end();
      return false;
    }
    if (!pass.interrupted) break;
    if (Status st = pass.seek(); !st) return st.error();
  }
  control.pass_end();
  return !stop();
}

}  // namespace rbsim::bag
