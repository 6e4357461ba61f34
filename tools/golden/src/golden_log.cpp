// Reading a golden log (golden_log.hpp) through the recording reader, in one pass: the per-step
// topics joined by step (their topics, order and counts checked by recordings::Recording), and in the
// same pass the raw messages of the scene description's topic and of the topics only the verifier
// reads (poses, /tf, the springs marker, the markers), each decoded into its collection.
#include "golden_log.hpp"

#include <algorithm>
#include <array>
#include <map>

#include "rbsim/recording.hpp"

namespace rbsim::check {

namespace {

using msgs::TopicId;

// The topics only the verifier reads (recordings::Recording joins the per-step ones).
constexpr std::array<TopicId, 4> kMarkerTopics = {TopicId::Poses, TopicId::Tf, TopicId::Springs,
                                                  TopicId::Markers};

class GoldenLogReader {
 public:
  explicit GoldenLogReader(const std::string& path) : path_(path) {}

  Result<GoldenLog> read() {
    recordings::RecordingOptions options;
    options.require_scene = false;  // a missing scene description is a failed check, not an error
    options.verify_crc = true;
    auto opened = recordings::Recording::open(path_, options);
    if (!opened) return opened.error();
    recording_ = std::move(opened.value());
    if (Status st = find_marker_topics(); !st) return st.error();
    if (Status st = read_messages(); !st) return st.error();
    return std::move(log_);
  }

 private:
  Error fail(const std::string& what) const { return Error{path_ + ": " + what}; }

  // Every channel of a marker topic's type that this build decodes (one topic per type).
  Status find_marker_topics() {
    std::array<std::string, msgs::kTopicCount> names;
    for (const recordings::RecordedChannel& c : recording_->channels()) {
      if (c.spec == nullptr || !c.problem.empty()) continue;
      const TopicId id = c.spec->id;
      if (std::find(kMarkerTopics.begin(), kMarkerTopics.end(), id) == kMarkerTopics.end()) continue;
      std::string& name = names[static_cast<std::size_t>(id)];
      if (!name.empty() && name != c.channel->topic) {
        return fail("two topics carry " + std::string(c.spec->type) + ": " + name + " and " +
                    c.channel->topic);
      }
      name = c.channel->topic;
      route_.emplace(c.channel->id, id);
    }
    log_.states.topic = recording_->topic(TopicId::BodyStates);
    log_.springs.topic = recording_->topic(TopicId::SpringStates);
    log_.energy.topic = recording_->topic(TopicId::Energy);
    log_.poses.topic = names[static_cast<std::size_t>(TopicId::Poses)];
    log_.tf.topic = names[static_cast<std::size_t>(TopicId::Tf)];
    log_.springs_marker.topic = names[static_cast<std::size_t>(TopicId::Springs)];
    log_.markers.topic = names[static_cast<std::size_t>(TopicId::Markers)];
    return Ok{};
  }

  // The one pass: steps from the recording reader, the other topics' messages beside them.
  Status read_messages() {
    recordings::MessageFilter also;
    if (const std::string& scene = recording_->topic(TopicId::SceneDescription); !scene.empty())
      also.topics.push_back(scene);
    for (const auto* to :
         {&log_.poses.topic, &log_.tf.topic, &log_.springs_marker.topic, &log_.markers.topic}) {
      if (!to->empty()) also.topics.push_back(*to);
    }
    if (recording_->scene() != nullptr) log_.scene.description = *recording_->scene();
    Status failure = Ok{};
    const auto on_message = [&](const recordings::RecordedMessage& m) {
      failure = dispatch(m);
      return static_cast<bool>(failure);
    };
    const Status st = recording_->read_steps([&](const recordings::RecordedStep& s) { return on_step(s); },
                                             also, on_message);
    if (!failure) return failure;
    return st;
  }

  Status on_step(const recordings::RecordedStep& s) {
    if (s.body_states != nullptr) log_.states.add(*s.body_states, s.log_time.body_states);
    if (s.spring_states != nullptr) log_.springs.add(*s.spring_states, s.log_time.spring_states);
    if (s.energy != nullptr) log_.energy.add(*s.energy, s.log_time.energy);
    return Ok{};
  }

  Status dispatch(const recordings::RecordedMessage& m) {
    // Every message of the scene description's type on its topic counts: one is expected.
    if (m.channel->spec != nullptr && m.channel->spec->id == TopicId::SceneDescription) {
      if (log_.scene.messages++ == 0) log_.scene.log_time = m.message->log_time;
      return Ok{};
    }
    const auto it = route_.find(m.message->channel_id);
    if (it == route_.end()) return Ok{};  // another channel of the same name
    const auto cdr = m.cdr();
    switch (it->second) {
      case TopicId::Poses:
        return on_marker_topic(msgs::decode_poses(cdr, poses_), m, poses_, log_.poses);
      case TopicId::Tf:
        return on_marker_topic(msgs::decode_tf(cdr, tf_), m, tf_, log_.tf);
      case TopicId::Springs:
        return on_marker_topic(msgs::decode_marker(cdr, marker_), m, marker_, log_.springs_marker);
      default:
        return on_marker_topic(msgs::decode_marker_array(cdr, markers_), m, markers_, log_.markers);
    }
  }

  template <class M>
  Status on_marker_topic(const Status& decoded, const recordings::RecordedMessage& m, const M& message,
                         TopicMessages<M>& to) {
    if (!decoded) {
      return fail(to.topic + " message " + std::to_string(to.messages.size()) + ": " +
                  decoded.error().message);
    }
    to.add(message, m.message->log_time);
    return Ok{};
  }

  std::string path_;
  std::unique_ptr<recordings::Recording> recording_;
  std::map<std::uint16_t, TopicId> route_;  // marker channel id -> the topic it carries
  GoldenLog log_;
  // Decoding targets, reused from one message to the next.
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
