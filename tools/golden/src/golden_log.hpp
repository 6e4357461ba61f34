// A golden log read whole (goldens are small) and typed, for the verifier's stages: the scene
// description and every topic a stage checks, each topic's messages in log-time order.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "rbsim/core.hpp"
#include "rbsim/mcap.hpp"
#include "rbsim/msgs.hpp"

namespace rbsim::check {

// The messages of one topic, with the log time of each.
template <class M>
struct TopicMessages {
  std::string topic;  // empty: the file has no such topic
  std::vector<M> messages;
  std::vector<mcap::Timestamp> log_time;
  void add(const M& m, mcap::Timestamp t) {
    messages.push_back(m);
    log_time.push_back(t);
  }
};

// The latched scene description: the first one, and how many there are and when the first came.
struct LatchedScene {
  std::optional<msgs::SceneMessage> description;  // none: absent, or of a schema this build cannot read
  std::uint64_t messages = 0;
  mcap::Timestamp log_time = 0;  // of the first
};

struct GoldenLog {
  LatchedScene scene;
  TopicMessages<msgs::BodyStatesMessage> states;
  TopicMessages<msgs::SpringStatesMessage> springs;
  TopicMessages<msgs::EnergyTermsMessage> energy;
  TopicMessages<msgs::PosesMessage> poses;
  TopicMessages<msgs::TfMessage> tf;
  TopicMessages<msgs::MarkerMessage> springs_marker;
  TopicMessages<std::vector<msgs::MarkerMessage>> markers;  // latched: one expected
};

// Reads `path` in one pass over its messages, each decoded and handed to the collection of its
// topic (topics found by type, as rbsim::recordings::Recording finds them). The one place the verifier
// opens a golden. A missing topic is not an error here (it is a failed check): errors are an
// unreadable or corrupt file, several topics of one type, a schema differing from this build's, a
// malformed message, a step that does not increase on its topic, or a per-step message whose
// counts differ from the scene description's.
Result<GoldenLog> read_golden_log(const std::string& path);

}  // namespace rbsim::check
