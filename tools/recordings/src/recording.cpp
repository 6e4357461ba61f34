// The recording reader: topics by type, the scene description first, per-step messages joined by
// their step.
#include "rbsim/recording.hpp"

#include <algorithm>
#include <array>
#include <deque>
#include <map>
#include <optional>

#include "rbsim/assert.hpp"
#include "rbsim/bag.hpp"
#include "rbsim/mcap_tools.hpp"

namespace rbsim::recordings {

namespace {

// The per-step topics the reader decodes, in RecordedStep's order.
constexpr std::array<msgs::TopicId, 3> kPerStep = {msgs::TopicId::BodyStates, msgs::TopicId::SpringStates,
                                                   msgs::TopicId::Energy};
constexpr std::size_t kStates = 0, kSprings = 1, kEnergy = 2;

int per_step_index(msgs::TopicId id) {
  for (std::size_t i = 0; i < kPerStep.size(); ++i) {
    if (kPerStep[i] == id) return static_cast<int>(i);
  }
  return -1;
}

}  // namespace

std::string_view RecordedChannel::schema_text() const {
  if (schema == nullptr) return {};
  return {reinterpret_cast<const char*>(schema->data.data()), schema->data.size()};
}

namespace {

// The schema of `channel` in `reader`, and how many messages the reader's summary counts on it.
const mcap::Schema* schema_of(const mcap::IndexedReader& reader, const mcap::Channel& channel) {
  const auto schema = reader.schemas().find(channel.schema_id);
  return schema == reader.schemas().end() ? nullptr : &schema->second;
}
std::optional<std::uint64_t> count_of(const mcap::IndexedReader& reader, std::uint16_t channel) {
  if (const auto& stats = reader.statistics()) {
    if (const auto n = stats->channel_message_counts.find(channel); n != stats->channel_message_counts.end())
      return n->second;
  }
  return std::nullopt;
}

// What this build makes of a channel: its rbsim topic (by schema name), whether it can decode it.
RecordedChannel describe_channel(const mcap::Channel& channel, const mcap::Schema* schema) {
  RecordedChannel c;
  c.channel = &channel;
  c.schema = schema;
  if (c.schema == nullptr) return c;
  c.spec = msgs::topic_for_type(c.schema->name);
  if (c.spec == nullptr) return c;
  const std::string type(c.spec->type);
  Result<std::string> ours = msgs::ros2msg_schema(type);
  const std::string_view text = c.schema_text();
  const auto energy_version = c.spec->id == msgs::TopicId::Energy && c.schema->encoding == "ros2msg"
                                  ? msgs::energy_terms_version(text)
                                  : std::nullopt;
  if (channel.message_encoding != "cdr") {
    c.problem = "message encoding \"" + channel.message_encoding + "\", not cdr";
  } else if (energy_version) {
    c.energy_version = *energy_version;
  } else if (!ours || c.schema->encoding != "ros2msg" || text != ours.value()) {
    c.problem = "its " + type + " schema differs from this build's (recorded by another version?)";
  }
  return c;
}

}  // namespace

// A recorded step's place: its segment (the world's run, one more each time the steps start again
// at 0: a reset, a world loaded) and its step in it. Steps are passed on in this order.
struct StepKey {
  std::uint32_t segment = 0;
  std::uint64_t step = 0;
  auto operator<=>(const StepKey&) const = default;
};

struct Recording::Impl {
  // The messages recorded for one step, as far as they have arrived.
  struct Slot {
    std::uint32_t segment = 0;
    std::uint64_t step = 0;
    StepKey key() const { return {segment, step}; }
    std::array<bool, kPerStep.size()> has{};
    msgs::BodyStatesMessage states;
    msgs::SpringStatesMessage springs;
    msgs::EnergyTermsMessage energy;
    RecordedStep::LogTimes log_time;
  };

  std::string path;
  RecordingOptions options;
  // One reader per file: one, or a bag's files in order, read as one recording through `join`
  // (rbsim/bag.hpp), whose repeat tracking each pass copies.
  std::vector<std::unique_ptr<mcap::IndexedReader>> readers;
  BagJoin join;
  // Every channel, in the order they became known (the summary's by id, then any a read found);
  // a deque, so the pointers handed out in RecordedMessage stay valid as channels are added.
  std::deque<RecordedChannel> channels;
  std::map<std::uint16_t, std::size_t> channel_at;  // channel id -> index in channels
  std::optional<msgs::SceneMessage> scene;
  std::uint64_t scene_step = 0;  // the step its stamp names
  std::array<std::string, msgs::kTopicCount> topics;
  std::map<std::uint16_t, msgs::TopicId> route;  // channel id -> the topic it carries
  msgs::EnergyTermsVersion energy_version = msgs::EnergyTermsVersion::Current;
  std::array<bool, kPerStep.size()> read{};     // decoded and joined
  std::array<bool, kPerStep.size()> present{};  // read and in the file: a step waits for them

  // Steps not passed on yet, by increasing step; spare slots keep their storage for reuse.
  std::vector<std::unique_ptr<Slot>> pending, spare;
  std::array<std::optional<StepKey>, kPerStep.size()> last;  // last step seen per topic
  // The epochs of a pass (RecordedStep). Where they start is known before the pass (the steps of
  // every scene description, in log-time order: nondecreasing within a segment, a description at
  // step 0 after the first starting the next segment, as a step 0 recorded again or a step that
  // goes back does on a per-step topic), so neither the epoch of a step nor
  // how often a step may be recorded again depends on how the topics' log times interleave (a
  // recorder that fell behind takes a topic's samples in a batch). The first epoch's description
  // is `scene`; later ones are decoded as the pass meets them, and one that no step still to come
  // can be in is dropped. No epochs are followed (epoch_starts empty) without a scene description
  // or a per-step topic.
  struct Epoch {
    std::uint32_t index = 0;
    msgs::SceneMessage scene;
  };
  std::vector<StepKey> epoch_starts;   // the segment and step of each scene description
  std::deque<Epoch> epochs;            // those after the first, decoded, the oldest still needed first
  std::uint32_t scenes_seen = 0;       // scene descriptions met in this pass
  std::uint32_t segments_dropped = 0;  // segments of a step 0 only, replaced (drain)
  // How many times each topic's last step came again (up to the epochs that start at it).
  std::array<std::uint32_t, kPerStep.size()> again_count{};
  msgs::BodyStatesMessage scratch_states;
  msgs::SpringStatesMessage scratch_springs;
  msgs::EnergyTermsMessage scratch_energy;

  Error fail(const std::string& what) const { return Error{path + ": " + what}; }

  // The description of `channel`, made the first time it is asked for (a bag's later files
  // define it again under the same id).
  RecordedChannel& described(const mcap::Channel& channel, const mcap::Schema* schema) {
    const auto [it, fresh] = channel_at.try_emplace(channel.id, channels.size());
    if (fresh) channels.push_back(describe_channel(channel, schema));
    return channels[it->second];
  }

  // The channel a message arrived on (one the summary did not list is described now).
  const RecordedChannel* channel_of(const mcap::MessageEntry& e) {
    return e.channel == nullptr ? nullptr : &described(*e.channel, e.schema);
  }

  Status learn_channels() {
    for (std::size_t k = 0; k < readers.size(); ++k) {
      for (const auto& [id, channel] : readers[k]->channels()) {
        bool repeat = false;
        if (Status st = join.channel(k, channel, repeat); !st) return fail(st.error().message);
        RecordedChannel& c = described(channel, schema_of(*readers[k], channel));
        if (const std::optional<std::uint64_t> n = count_of(*readers[k], id))
          c.message_count = c.message_count.value_or(0) + *n;
      }
    }
    return Ok{};
  }

  // Every file's messages `ro` picks, file after file (each in log-time order), a split's
  // repeats of latched messages skipped, until `on` returns false.
  Status each_message(const mcap::ReadMessagesOptions& ro,
                      const std::function<bool(const mcap::MessageEntry&)>& on) {
    BagJoin pass = join;
    bool stopped = false;
    for (std::size_t k = 0; k < readers.size() && !stopped; ++k) {
      const Status st = readers[k]->read_messages(ro, [&](const mcap::MessageEntry& e) {
        if (readers.size() > 1 && pass.repeated(k, e.message)) return true;
        stopped = !on(e);
        return !stopped;
      });
      if (!st.ok()) return st;
    }
    return Ok{};
  }

  Status classify() {
    for (const RecordedChannel& c : channels) {
      if (c.spec == nullptr) continue;
      const msgs::TopicId id = c.spec->id;
      const int i = per_step_index(id);
      // The scene description when asked for, the per-step topics read, and the commands (an event
      // topic, read whole by read_commands).
      const bool commands = id == msgs::TopicId::Commands;
      if (id == msgs::TopicId::SceneDescription ? !options.scene
                                                : !commands && (i < 0 || !read[static_cast<std::size_t>(i)]))
        continue;
      if (!options.ns.empty() && c.channel->topic != msgs::topic_name(*c.spec, options.ns)) continue;
      std::string& topic = topics[static_cast<std::size_t>(id)];
      if (!topic.empty() && topic != c.channel->topic) {
        return fail("several " + std::string(c.spec->type) + " topics (" + topic + ", " + c.channel->topic +
                    "): choose one recording with --namespace");
      }
      if (!c.problem.empty()) {
        if ((id == msgs::TopicId::SceneDescription && !options.require_scene) || commands) continue;
        return fail("topic " + c.channel->topic + ": " + c.problem + ": cannot read it");
      }
      topic = c.channel->topic;
      route.emplace(c.channel->id, id);
      if (id == msgs::TopicId::Energy) energy_version = c.energy_version;
      if (i >= 0) present[static_cast<std::size_t>(i)] = true;
    }
    return Ok{};
  }

  Error missing(msgs::TopicId id) const {
    return fail("no " + std::string(msgs::topic(id).type) + " topic" +
                (options.ns.empty() ? std::string() : " in namespace '" + options.ns + "'") +
                " (recorded by rbsim run --record?)");
  }

  std::string where(const mcap::MessageEntry& e) const {
    return "message at log time " + mcap_tools::seconds(e.message.log_time) + " s on " +
           (e.channel != nullptr ? e.channel->topic : std::string("?"));
  }

  // Each message of the scene description's topic in log-time order, until `on` returns false or
  // sets `failure`.
  Status each_scene(const std::function<bool(const mcap::MessageEntry&, Status& failure)>& on) {
    mcap::ReadMessagesOptions ro;
    ro.topics.push_back(topics[static_cast<std::size_t>(msgs::TopicId::SceneDescription)]);
    Status failure = Ok{};
    const Status st = each_message(ro, [&](const mcap::MessageEntry& e) {
      const auto r = route.find(e.message.channel_id);
      if (r == route.end() || r->second != msgs::TopicId::SceneDescription) return true;
      return on(e, failure) && static_cast<bool>(failure);
    });
    if (!st.ok()) return fail(mcap_tools::read_error(st.error()));
    return failure;
  }

  Status read_scene() {
    const std::string& topic = topics[static_cast<std::size_t>(msgs::TopicId::SceneDescription)];
    if (topic.empty()) return Ok{};
    const Status st = each_scene([&](const mcap::MessageEntry& e, Status& failure) {
      Result<msgs::SceneMessage> decoded = msgs::decode_scene(e.message.data);
      if (!decoded) {
        failure = fail(where(e) + ": " + decoded.error().message);
        return false;
      }
      scene = std::move(decoded.value());
      scene_step = msgs::message_step(msgs::TopicId::SceneDescription, e.message.data, scene->dt).value_or(0);
      return false;  // the first: a later one starts an epoch (read_steps)
    });
    if (!st) return st;
    if (!scene && options.require_scene) {
      return fail("no scene description recorded (topic " + topic + " of type " +
                  std::string(msgs::topic(msgs::TopicId::SceneDescription).type) + " has no messages)");
    }
    return Ok{};
  }

  // Where the epochs start: the step of every scene description, in log-time order (one read of
  // that topic's messages; none when the summary counts a single one).
  Status find_epochs() {
    epoch_starts.assign(1, StepKey{0, scene_step});
    const std::string& topic = topics[static_cast<std::size_t>(msgs::TopicId::SceneDescription)];
    for (const RecordedChannel& c : channels) {
      if (c.channel->topic == topic && c.message_count == 1u) return Ok{};
    }
    epoch_starts.clear();
    const Status st = each_scene([&](const mcap::MessageEntry& e, Status& failure) {
      const std::optional<std::uint64_t> at =
          msgs::message_step(msgs::TopicId::SceneDescription, e.message.data, scene->dt);
      if (!at) {
        failure = fail(where(e) + ": a scene description without a stamp of dt " + std::to_string(scene->dt));
      } else if (!epoch_starts.empty() && *at != 0 && *at < epoch_starts.back().step) {
        failure = fail(where(e) + ": a scene description of step " + std::to_string(*at) +
                       " after one of step " + std::to_string(epoch_starts.back().step) +
                       " (steps increase until a restart's description of step 0)");
      }
      if (!failure) return false;
      // A description of step 0 after the first: the steps start again (a reset, a world loaded).
      const std::uint32_t segment =
          epoch_starts.empty() ? 0 : epoch_starts.back().segment + (*at == 0 ? 1u : 0u);
      epoch_starts.push_back(StepKey{segment, *at});
      return true;
    });
    if (!st) return st;
    if (epoch_starts.empty()) epoch_starts.push_back(StepKey{0, scene_step});
    return Ok{};
  }

  // The epoch a step is in: the last whose scene description starts at or before it (the first for
  // a step before every start: a recorder that joined late holds the latest description only).
  std::uint32_t epoch_index(StepKey step) const {
    const auto after = std::upper_bound(epoch_starts.begin(), epoch_starts.end(), step);
    return after == epoch_starts.begin() ? 0u : static_cast<std::uint32_t>(after - epoch_starts.begin() - 1);
  }
  // How many epochs start at `step` after the first: how often the step may be recorded again.
  std::uint32_t changes_at(StepKey step) const {
    const auto [from, to] = std::equal_range(epoch_starts.begin() + 1, epoch_starts.end(), step);
    return static_cast<std::uint32_t>(to - from);
  }

  // A scene description met in a pass: the first epoch's was read by open; each later one decoded.
  Status scene_message(const mcap::MessageEntry& e) {
    const std::uint32_t index = scenes_seen++;
    if (index == 0 || epoch_starts.empty()) return Ok{};
    Result<msgs::SceneMessage> decoded = msgs::decode_scene(e.message.data);
    if (!decoded) return fail(where(e) + ": " + decoded.error().message);
    epochs.push_back({index, std::move(decoded.value())});
    return Ok{};
  }

  // The description of epoch `index`, for a step ready to be passed on (its description met); older
  // ones are dropped, as steps are passed on in increasing order.
  const msgs::SceneMessage& epoch_scene(std::uint32_t index) {
    if (index == 0) return *scene;
    while (!epochs.empty() && epochs.front().index < index) epochs.pop_front();
    RBSIM_ASSERT(!epochs.empty() && epochs.front().index == index,
                 "a step is passed on once its scene description was read");
    return epochs.front().scene;
  }

  Slot& slot_for(StepKey step) {
    std::size_t pos = pending.size();
    while (pos > 0 && pending[pos - 1]->key() > step) --pos;
    if (pos > 0 && pending[pos - 1]->key() == step) return *pending[pos - 1];
    std::unique_ptr<Slot> s;
    if (spare.empty()) {
      s = std::make_unique<Slot>();
    } else {
      s = std::move(spare.back());
      spare.pop_back();
    }
    s->segment = step.segment;
    s->step = step.step;
    s->has = {};
    s->log_time = {};
    Slot& slot = **pending.insert(pending.begin() + static_cast<std::ptrdiff_t>(pos), std::move(s));
    RBSIM_ASSERT((pos == 0 || pending[pos - 1]->key() < step) &&
                     (pos + 1 == pending.size() || pending[pos + 1]->key() > step),
                 "the steps waiting to be joined are distinct and in order");
    return slot;
  }

  Status message(const mcap::MessageEntry& e, std::size_t i) {
    const ByteView cdr = e.message.data;
    Status decoded = Ok{};
    switch (i) {
      case kStates:
        decoded = msgs::decode_body_states(cdr, scratch_states);
        break;
      case kSprings:
        decoded = msgs::decode_spring_states(cdr, scratch_springs);
        break;
      default:
        decoded = msgs::decode_energy_terms(cdr, scratch_energy, energy_version);
        break;
    }
    if (!decoded) return fail(where(e) + ": " + decoded.error().message);
    // The step these types carry; decoding checked that the message holds it.
    const std::optional<std::uint64_t> at = msgs::message_step(kPerStep[i], cdr, scene ? scene->dt : 0.0);
    RBSIM_ASSERT(at.has_value(), "a decoded per-step message carries its step");
    // The steps start again (a reset, a world loaded: step 0 again, or a step that goes back): the
    // topic's next segment.
    StepKey step{last[i] ? last[i]->segment : 0u, *at};
    if (last[i] && (*at < last[i]->step || (*at == 0 && last[i]->step == 0))) ++step.segment;
    // The step of a change recorded again (once per epoch that starts at it): the last one wins.
    const bool again =
        last[i] && step == *last[i] && !epoch_starts.empty() && again_count[i] < changes_at(step);
    again_count[i] = again ? again_count[i] + 1 : 0;
    if (last[i] && step == *last[i] && !again) {
      return fail(where(e) + ": step " + std::to_string(*at) + " has two " +
                  std::string(msgs::topic(kPerStep[i]).type) + " messages");
    }
    last[i] = step;
    Slot& s = slot_for(step);
    s.has[i] = true;
    switch (i) {
      case kStates:
        std::swap(s.states, scratch_states);
        s.log_time.body_states = e.message.log_time;
        break;
      case kSprings:
        std::swap(s.springs, scratch_springs);
        s.log_time.spring_states = e.message.log_time;
        break;
      default:
        std::swap(s.energy, scratch_energy);
        s.log_time.energy = e.message.log_time;
        break;
    }
    return Ok{};
  }

  // Whether every read topic has moved past the oldest pending step (until then, a change may still
  // record it again).
  bool ready(const Slot& s) const {
    for (std::size_t i = 0; i < kPerStep.size(); ++i) {
      if (present[i] && !(last[i] && *last[i] > s.key())) return false;
    }
    return epoch_starts.empty() || epoch_index(s.key()) < scenes_seen;  // and its description was met
  }

  Status check(const Slot& s, const msgs::SceneMessage* described) const {
    if (described == nullptr) return Ok{};
    const std::string at = "step " + std::to_string(s.step) + ": ";
    const std::size_t bodies = described->bodies.size(), springs = described->springs.size();
    const auto count = [&](msgs::TopicId id, const char* what, std::size_t got, std::size_t want) -> Status {
      if (got == want) return Ok{};
      return fail(at + topics[static_cast<std::size_t>(id)] + " has " + std::to_string(got) + " " + what +
                  ", the scene description " + std::to_string(want));
    };
    if (s.has[kStates]) {
      if (Status st = count(msgs::TopicId::BodyStates, "bodies", s.states.bodies.size(), bodies); !st)
        return st;
    }
    if (s.has[kSprings]) {
      if (Status st = count(msgs::TopicId::SpringStates, "springs", s.springs.springs.size(), springs); !st)
        return st;
    }
    if (s.has[kEnergy]) {
      if (Status st = count(msgs::TopicId::Energy, "bodies", s.energy.bodies.size(), bodies); !st) return st;
      std::size_t gravity = 0;
      for (const auto& f : s.energy.forces) {
        if (f.kind == static_cast<std::uint8_t>(msgs::EnergyTermsMessage::ForceKind::Gravity)) ++gravity;
      }
      if (Status st = count(msgs::TopicId::Energy, "gravity potentials", gravity, described->gravity.size());
          !st)
        return st;
      if (Status st =
              count(msgs::TopicId::Energy, "spring potentials", s.energy.forces.size() - gravity, springs);
          !st)
        return st;
    }
    return Ok{};
  }

  // Passes on the oldest pending steps that are ready (all of them when `all`).
  Status drain(bool all, const std::function<Status(const RecordedStep&)>& on_step) {
    std::size_t done = 0;
    Status result = Ok{};
    while (done < pending.size() && (all || ready(*pending[done]))) {
      const Slot& s = *pending[done];
      ++done;
      // A world's step 0 replaced before it stepped (a change at step 0, or a restart from there):
      // as at a later step, the last recording of the step wins, and the segment it ended goes.
      if (s.step == 0 && done < pending.size() && pending[done]->key() == StepKey{s.segment + 1, 0}) {
        ++segments_dropped;
        continue;
      }
      RecordedStep step;
      step.step = s.step;
      step.segment = s.segment - segments_dropped;
      if (!epoch_starts.empty()) {
        step.epoch = epoch_index(s.key());
        step.scene = &epoch_scene(step.epoch);
      }
      if (result = check(s, step.scene); !result) break;
      if (s.has[kStates]) step.body_states = &s.states;
      if (s.has[kSprings]) step.spring_states = &s.springs;
      if (s.has[kEnergy]) step.energy = &s.energy;
      step.log_time = s.log_time;
      if (result = on_step(step); !result) break;
    }
    for (std::size_t k = 0; k < done; ++k) spare.push_back(std::move(pending[k]));
    pending.erase(pending.begin(), pending.begin() + static_cast<std::ptrdiff_t>(done));
    return result;
  }
};

Recording::Recording() : impl_(std::make_unique<Impl>()) {}
Recording::~Recording() = default;

Result<std::unique_ptr<Recording>> Recording::open(const std::string& given,
                                                   const RecordingOptions& options) {
  // A bag directory is read through its files (rbsim/bag.hpp).
  const Result<std::vector<std::string>> files = recording_files(given);
  if (!files) return files.error();
  std::unique_ptr<Recording> r(new Recording());
  Impl& im = *r->impl_;
  im.path = given;
  im.options = options;
  for (msgs::TopicId id : options.read) {
    const int i = per_step_index(id);
    if (i < 0) return im.fail("cannot read " + std::string(msgs::topic(id).type) + " messages as steps");
    im.read[static_cast<std::size_t>(i)] = true;
  }
  if (options.read.empty() && options.steps) im.read.fill(true);
  for (msgs::TopicId id : options.require) {
    const int i = per_step_index(id);
    if (i < 0 || !im.read[static_cast<std::size_t>(i)]) {
      return im.fail("cannot require " + std::string(msgs::topic(id).type) + " without reading it");
    }
  }
  for (const std::string& file : files.value()) {
    im.path = file;  // what errors name
    if (std::string e = mcap_tools::unreadable(file); !e.empty()) return im.fail(e);
    auto& reader = *im.readers.emplace_back(std::make_unique<mcap::IndexedReader>());
    if (Status s = reader.open(file); !s.ok()) return im.fail(mcap_tools::read_error(s.error()));
    if (options.verify_crc) {
      if (Status s = reader.verify_data_section_crc(); !s.ok())
        return im.fail(mcap_tools::read_error(s.error()));
    }
    // A file whose summary lists no channels defines them in its data section: read it once to
    // learn them.
    if (reader.channels().empty()) {
      const Status s = reader.read_messages({}, [](const mcap::MessageEntry&) { return true; });
      if (!s.ok()) return im.fail(mcap_tools::read_error(s.error()));
    }
  }
  im.path = files->size() == 1 ? files->front() : given;
  if (Status st = im.learn_channels(); !st) return st.error();
  if (Status st = im.classify(); !st) return st.error();
  if (options.scene && options.require_scene &&
      im.topics[static_cast<std::size_t>(msgs::TopicId::SceneDescription)].empty()) {
    return im.missing(msgs::TopicId::SceneDescription);
  }
  for (msgs::TopicId id : options.require) {
    if (im.topics[static_cast<std::size_t>(id)].empty()) return im.missing(id);
  }
  if (Status st = im.read_scene(); !st) return st.error();
  return r;
}

const std::string& Recording::path() const {
  return impl_->path;
}

const msgs::SceneMessage* Recording::scene() const {
  return impl_->scene ? &*impl_->scene : nullptr;
}

const std::string& Recording::topic(msgs::TopicId id) const {
  return impl_->topics[static_cast<std::size_t>(id)];
}

const std::deque<RecordedChannel>& Recording::channels() const {
  return impl_->channels;
}

const mcap::Header& Recording::header() const {
  return impl_->readers.front()->header();
}

bool Recording::lists_every_channel() const {
  for (const auto& reader : impl_->readers) {
    if (!reader->indexed()) return false;
    for (const mcap::ChunkIndex& ci : reader->chunk_indexes()) {
      if (ci.message_index_offsets.empty()) return false;
      for (const auto& [channel_id, offset] : ci.message_index_offsets) {
        if (reader->channels().count(channel_id) == 0) return false;
      }
    }
  }
  return true;
}

std::optional<mcap::Timestamp> Recording::last_log_time() const {
  std::optional<mcap::Timestamp> last;
  for (const auto& reader : impl_->readers) {
    for (const mcap::ChunkIndex& ci : reader->chunk_indexes())
      last = std::max(last.value_or(0), ci.message_end_time);
    if (const auto& stats = reader->statistics()) last = std::max(last.value_or(0), stats->message_end_time);
  }
  return last;
}

const std::vector<mcap::ChunkIndex>& Recording::chunk_indexes() const {
  // Chunks are served whole from one file only: a bag's files each have offsets of their own.
  static const std::vector<mcap::ChunkIndex> none;
  return impl_->readers.size() == 1 ? impl_->readers.front()->chunk_indexes() : none;
}

Result<Recording::RawChunk> Recording::read_chunk(const mcap::ChunkIndex& index, bool verify) {
  Impl& im = *impl_;
  RawChunk raw;
  auto chunk = im.readers.front()->read_chunk(index, verify);
  if (!chunk) return im.fail(mcap_tools::read_error(chunk.error()));
  raw.chunk = std::move(chunk.value());
  auto indexes = im.readers.front()->read_message_indexes(index);
  if (!indexes) return im.fail(mcap_tools::read_error(indexes.error()));
  raw.indexes = std::move(indexes.value());
  return raw;
}

Status Recording::read_messages(const MessageFilter& filter, const MessageCallback& on_message) {
  Impl& im = *impl_;
  const mcap::ReadMessagesOptions ro{filter.topics, filter.start, filter.end, filter.skip_chunks};
  const Status st = im.each_message(ro, [&](const mcap::MessageEntry& e) {
    const RecordedChannel* channel = im.channel_of(e);
    if (channel == nullptr) return true;  // a message on a channel the file never defines
    return on_message(RecordedMessage{channel, &e.message});
  });
  if (!st.ok()) return im.fail(mcap_tools::read_error(st.error()));
  return Ok{};
}

Status Recording::read_steps(const std::function<Status(const RecordedStep&)>& on_step,
                             const MessageFilter& also, const MessageCallback& on_message) {
  Impl& im = *impl_;
  im.pending.clear();
  im.last = {};
  im.again_count = {};
  im.epoch_starts.clear();
  im.epochs.clear();
  im.scenes_seen = 0;
  im.segments_dropped = 0;
  const bool any_steps = std::find(im.present.begin(), im.present.end(), true) != im.present.end();
  if (im.scene && any_steps) {
    if (Status st = im.find_epochs(); !st) return st;
  }
  mcap::ReadMessagesOptions ro;
  for (std::size_t i = 0; i < kPerStep.size(); ++i) {
    if (im.present[i]) ro.topics.push_back(im.topics[static_cast<std::size_t>(kPerStep[i])]);
  }
  // The scene descriptions, for the epochs (only when there are steps to put in them).
  const std::string& scene_topic = im.topics[static_cast<std::size_t>(msgs::TopicId::SceneDescription)];
  if (im.scene && !ro.topics.empty()) ro.topics.push_back(scene_topic);
  const std::size_t step_topics = ro.topics.size();
  if (on_message) ro.topics.insert(ro.topics.end(), also.topics.begin(), also.topics.end());
  if (ro.topics.empty()) return Ok{};
  const auto is_also = [&](const mcap::MessageEntry& e) {
    if (!on_message || e.channel == nullptr || e.message.log_time < also.start ||
        e.message.log_time >= also.end)
      return false;
    return std::find(ro.topics.begin() + static_cast<std::ptrdiff_t>(step_topics), ro.topics.end(),
                     e.channel->topic) != ro.topics.end();
  };
  Status failure = Ok{};
  bool stopped = false;
  const Status st = im.each_message(ro, [&](const mcap::MessageEntry& e) {
    const auto r = im.route.find(e.message.channel_id);
    const int i = r == im.route.end() ? -1 : per_step_index(r->second);
    if (r != im.route.end() && r->second == msgs::TopicId::SceneDescription) {
      failure = im.scene_message(e);
      if (!failure) return false;
    }
    if (i < 0) {
      // Not a joined topic: a raw message of `also`, or another channel of a joined topic's name.
      if (!is_also(e)) return true;
      const RecordedChannel* channel = im.channel_of(e);
      stopped = channel != nullptr && !on_message(RecordedMessage{channel, &e.message});
      return !stopped;
    }
    failure = im.message(e, static_cast<std::size_t>(i));
    if (failure) failure = im.drain(false, on_step);
    return static_cast<bool>(failure);
  });
  if (!st.ok()) return im.fail(mcap_tools::read_error(st.error()));
  if (!failure || stopped) return failure;
  return im.drain(true, on_step);
}

}  // namespace rbsim::recordings
