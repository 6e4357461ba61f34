// Reading a golden log (golden_log.hpp): topics by type, then one pass over the messages that
// hands each to the collection of its topic. The topics and errors are rbsim::log::Recording's
// for the scene description and the per-step topics it joins; this reader also decodes the
// topics Recording does not serve (poses, /tf, the springs marker, the markers), so the verifier
// reads the file once.
#include "golden_log.hpp"

#include <algorithm>
#include <array>
#include <map>
#include <set>

#include "rbsim/mcap_tools.hpp"
#include "rbsim/recording.hpp"

namespace rbsim::check {

namespace {

using msgs::TopicId;

// The topics the verifier reads: those Recording finds (the scene description and the steps it
// joins), then those only the verifier reads.
constexpr std::array<TopicId, 4> kRecordingTopics = {TopicId::Scene, TopicId::BodyStates,
                                                     TopicId::SpringStates, TopicId::Energy};
constexpr std::array<TopicId, 4> kMarkerTopics = {TopicId::Poses, TopicId::Tf, TopicId::Springs,
                                                  TopicId::Markers};

template <std::size_t N>
bool one_of(const std::array<TopicId, N>& ids, TopicId id) {
  return std::find(ids.begin(), ids.end(), id) != ids.end();
}

std::span<const std::byte> bytes_of(const mcap::Message& m) {
  return {reinterpret_cast<const std::byte*>(m.data.data()), m.data.size()};
}

class GoldenLogReader {
 public:
  explicit GoldenLogReader(const std::string& path) : path_(path) {}

  Result<GoldenLog> read() {
    if (Status st = open(); !st) return st.error();
    if (Status st = find_topics(); !st) return st.error();
    if (Status st = read_messages(); !st) return st.error();
    if (Status st = check_counts(); !st) return st.error();
    return std::move(log_);
  }

 private:
  Error fail(const std::string& what) const { return Error{path_ + ": " + what}; }

  std::string where(const mcap::MessageEntry& e) const {
    return "message at log time " + mcap_tools::seconds(e.message.log_time) + " s on " +
           (e.channel != nullptr ? e.channel->topic : std::string("?"));
  }

  std::string& topic(TopicId id) { return topics_[static_cast<std::size_t>(id)]; }

  Status open() {
    if (std::string e = mcap_tools::unreadable(path_); !e.empty()) return fail(e);
    if (Status s = reader_.open(path_); !s.ok()) return fail(mcap_tools::read_error(s.error()));
    if (Status s = reader_.verify_data_section_crc(); !s.ok()) return fail(mcap_tools::read_error(s.error()));
    // A file whose summary lists no channels defines them in its data section: only reading it
    // makes them known (a recording cut short; rbsim's goldens have a summary).
    if (reader_.channels().empty()) {
      const Status s = reader_.read_messages({}, [](const mcap::MessageEntry&) { return true; });
      if (!s.ok()) return fail(mcap_tools::read_error(s.error()));
    }
    return Ok{};
  }

  // Every channel of a type the verifier reads, routed to its topic. Recording's rules for its
  // topics first (so its errors come first): one topic per type, a schema this build decodes (a
  // scene description it cannot decode is a missing one); then the marker topics, where a channel
  // this build cannot decode is left out.
  Status find_topics() {
    const std::vector<log::RecordedChannel> channels = log::recorded_channels(reader_);
    for (const log::RecordedChannel& c : channels) {
      const TopicId id = c.spec->id;
      if (!one_of(kRecordingTopics, id)) continue;
      std::string& name = topic(id);
      if (!name.empty() && name != c.channel->topic) {
        return fail("several " + std::string(c.spec->type) + " topics (" + name + ", " + c.channel->topic +
                    "): choose one recording with --namespace");
      }
      if (!c.problem.empty()) {
        if (id == TopicId::Scene) continue;
        return fail("topic " + c.channel->topic + ": " + c.problem + ": cannot read it");
      }
      name = c.channel->topic;
      route_.emplace(c.channel->id, id);
      if (id == TopicId::Scene) decodable_scene_.insert(c.channel->id);
      if (id == TopicId::Energy) energy_version_ = c.energy_version;
    }
    for (const log::RecordedChannel& c : channels) {
      const TopicId id = c.spec->id;
      // Every message on the scene description's topic counts: one is expected.
      if (id == TopicId::Scene && !topic(id).empty() && c.channel->topic == topic(id)) {
        route_.emplace(c.channel->id, id);
      }
      if (!one_of(kMarkerTopics, id) || !c.problem.empty()) continue;
      std::string& name = topic(id);
      if (!name.empty() && name != c.channel->topic) {
        return fail("two topics carry " + std::string(c.spec->type) + ": " + name + " and " +
                    c.channel->topic);
      }
      name = c.channel->topic;
      route_.emplace(c.channel->id, id);
    }
    log_.states.topic = topic(TopicId::BodyStates);
    log_.springs.topic = topic(TopicId::SpringStates);
    log_.energy.topic = topic(TopicId::Energy);
    log_.poses.topic = topic(TopicId::Poses);
    log_.tf.topic = topic(TopicId::Tf);
    log_.springs_marker.topic = topic(TopicId::Springs);
    log_.markers.topic = topic(TopicId::Markers);
    return Ok{};
  }

  // The one pass over the file's messages, in log-time order; it stops at the first bad message.
  Status read_messages() {
    mcap::ReadMessagesOptions o;
    for (TopicId id : kRecordingTopics) {
      if (!topic(id).empty()) o.topics.push_back(topic(id));
    }
    for (TopicId id : kMarkerTopics) {
      if (!topic(id).empty()) o.topics.push_back(topic(id));
    }
    if (o.topics.empty()) return Ok{};
    Status failure = Ok{};
    const Status st = reader_.read_messages(o, [&](const mcap::MessageEntry& e) {
      const auto it = route_.find(e.message.channel_id);
      if (it == route_.end()) return true;  // another channel of the same name
      failure = dispatch(e, it->second);
      return static_cast<bool>(failure);
    });
    if (!st.ok()) return fail(mcap_tools::read_error(st.error()));
    return failure;
  }

  Status dispatch(const mcap::MessageEntry& e, TopicId id) {
    const auto cdr = bytes_of(e.message);
    switch (id) {
      case TopicId::Scene:
        return on_scene(e);
      case TopicId::BodyStates:
        return on_step(e, msgs::decode_body_states(cdr, scratch_states_), scratch_states_, log_.states);
      case TopicId::SpringStates:
        return on_step(e, msgs::decode_spring_states(cdr, scratch_springs_), scratch_springs_, log_.springs);
      case TopicId::Energy:
        return on_step(e, msgs::decode_energy_terms(cdr, scratch_energy_, energy_version_), scratch_energy_,
                       log_.energy);
      case TopicId::Poses:
        return on_marker_topic(msgs::decode_poses(cdr, poses_), e, poses_, log_.poses);
      case TopicId::Tf:
        return on_marker_topic(msgs::decode_tf(cdr, tf_), e, tf_, log_.tf);
      case TopicId::Springs:
        return on_marker_topic(msgs::decode_marker(cdr, marker_), e, marker_, log_.springs_marker);
      case TopicId::Markers:
        return on_marker_topic(msgs::decode_marker_array(cdr, markers_), e, markers_, log_.markers);
      default:
        return Ok{};
    }
  }

  // The scene description is latched: the first decodable one is read, a repeat only counted.
  Status on_scene(const mcap::MessageEntry& e) {
    LatchedScene& scene = log_.scene;
    if (scene.messages++ == 0) scene.log_time = e.message.log_time;
    if (scene.description || decodable_scene_.count(e.message.channel_id) == 0) return Ok{};
    Result<msgs::SceneMessage> decoded = msgs::decode_scene(bytes_of(e.message));
    if (!decoded) return fail(where(e) + ": " + decoded.error().message);
    scene.description = std::move(decoded.value());
    return Ok{};
  }

  // A per-step message: its step must increase on its topic (a repeat or a step back means two
  // runs in one file).
  template <class M>
  Status on_step(const mcap::MessageEntry& e, const Status& decoded, const M& message, TopicMessages<M>& to) {
    if (!decoded) return fail(where(e) + ": " + decoded.error().message);
    if (!to.messages.empty() && message.step <= to.messages.back().step) {
      const std::uint64_t last = to.messages.back().step;
      const std::string type(msgs::topic(topic_id(to)).type);
      if (message.step == last)
        return fail(where(e) + ": step " + std::to_string(message.step) + " has two " + type + " messages");
      return fail(where(e) + ": step " + std::to_string(message.step) + " after step " +
                  std::to_string(last) + " (steps must increase: a recording of several runs?)");
    }
    to.add(message, e.message.log_time);
    return Ok{};
  }

  TopicId topic_id(const TopicMessages<msgs::BodyStatesMessage>&) const { return TopicId::BodyStates; }
  TopicId topic_id(const TopicMessages<msgs::SpringStatesMessage>&) const { return TopicId::SpringStates; }
  TopicId topic_id(const TopicMessages<msgs::EnergyTermsMessage>&) const { return TopicId::Energy; }

  template <class M>
  Status on_marker_topic(const Status& decoded, const mcap::MessageEntry& e, const M& message,
                         TopicMessages<M>& to) {
    if (!decoded) {
      return fail(to.topic + " message " + std::to_string(to.messages.size()) + ": " +
                  decoded.error().message);
    }
    to.add(message, e.message.log_time);
    return Ok{};
  }

  // Each step's messages against the scene description: as many bodies, springs, and gravity and
  // spring potentials; steps in increasing order, the topics of one step in Recording's order.
  Status check_counts() const {
    if (!log_.scene.description) return Ok{};
    const msgs::SceneMessage& scene = *log_.scene.description;
    const auto count = [&](const std::string& name, std::uint64_t step, const char* what, std::size_t got,
                           std::size_t want) -> Status {
      if (got == want) return Ok{};
      return fail("step " + std::to_string(step) + ": " + name + " has " + std::to_string(got) + " " + what +
                  ", the scene description " + std::to_string(want));
    };
    std::size_t s = 0, p = 0, e = 0;
    const auto& states = log_.states.messages;
    const auto& springs = log_.springs.messages;
    const auto& energy = log_.energy.messages;
    while (s < states.size() || p < springs.size() || e < energy.size()) {
      std::uint64_t step = UINT64_MAX;
      if (s < states.size()) step = std::min(step, states[s].step);
      if (p < springs.size()) step = std::min(step, springs[p].step);
      if (e < energy.size()) step = std::min(step, energy[e].step);
      if (s < states.size() && states[s].step == step) {
        if (Status st =
                count(log_.states.topic, step, "bodies", states[s++].bodies.size(), scene.bodies.size());
            !st)
          return st;
      }
      if (p < springs.size() && springs[p].step == step) {
        if (Status st =
                count(log_.springs.topic, step, "springs", springs[p++].springs.size(), scene.springs.size());
            !st)
          return st;
      }
      if (e < energy.size() && energy[e].step == step) {
        if (Status st = check_energy_counts(energy[e++], step, count); !st) return st;
      }
    }
    return Ok{};
  }

  template <class Count>
  Status check_energy_counts(const msgs::EnergyTermsMessage& m, std::uint64_t step,
                             const Count& count) const {
    const msgs::SceneMessage& scene = *log_.scene.description;
    const std::string& name = log_.energy.topic;
    if (Status st = count(name, step, "bodies", m.bodies.size(), scene.bodies.size()); !st) return st;
    std::size_t gravity = 0;
    for (const auto& f : m.forces) {
      if (f.kind == static_cast<std::uint8_t>(msgs::EnergyTermsMessage::ForceKind::Gravity)) ++gravity;
    }
    if (Status st = count(name, step, "gravity potentials", gravity, scene.gravity.size()); !st) return st;
    return count(name, step, "spring potentials", m.forces.size() - gravity, scene.springs.size());
  }

  std::string path_;
  mcap::IndexedReader reader_;
  std::array<std::string, msgs::kTopicCount> topics_;
  std::map<std::uint16_t, TopicId> route_;  // channel id -> the topic it carries
  std::set<std::uint16_t> decodable_scene_;
  msgs::EnergyTermsVersion energy_version_ = msgs::EnergyTermsVersion::Current;
  GoldenLog log_;
  // Decoding targets, reused from one message to the next.
  msgs::BodyStatesMessage scratch_states_;
  msgs::SpringStatesMessage scratch_springs_;
  msgs::EnergyTermsMessage scratch_energy_;
  msgs::PosesMessage poses_;
  msgs::TfMessage tf_;
  msgs::MarkerMessage marker_;
  std::vector<msgs::MarkerMessage> markers_;
};

}  // namespace

Result<GoldenLog> read_golden_log(const std::string& path) {
  return GoldenLogReader(path).read();
}

}  // namespace rbsim::check
