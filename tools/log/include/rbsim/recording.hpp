// Reading a recording back: the one reader of rbsim's MCAP recordings (render, plot, export,
// golden verification and replay use it). Topics are found by type from msgs::topics(), never by
// name; messages are decoded by this build's typed decoders, so a channel whose schema text differs
// from this build's is refused rather than misread.
//
// A recording's messages may arrive in any log-time order: a live recording (rbsim record, DDS)
// stamps each message with its arrival time, so the latched scene description can come after the
// first body states and the per-step topics of one step interleave with those of the next. The
// reader reads the scene description first, wherever it is in the file, and joins the per-step
// messages of different topics by the step they carry.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "rbsim/core.hpp"
#include "rbsim/mcap.hpp"
#include "rbsim/msgs.hpp"

namespace rbsim::log {

// ---------------------------------------------------------------------------------------------
// Channels by type

// A channel of a recording that carries one of our types.
struct RecordedChannel {
  const mcap::Channel* channel = nullptr;  // points into the reader's channels()
  const msgs::TopicSpec* spec = nullptr;
  // Empty when the channel can be decoded by this build (message encoding "cdr", a "ros2msg"
  // schema whose text equals this build's); otherwise why not, e.g. "its rbsim_msgs/msg/BodyStates
  // schema differs from this build's (recorded by another version?)".
  std::string problem;
  // The layout of an EnergyTerms channel: a recording made before the potential split is read too.
  msgs::EnergyTermsVersion energy_version = msgs::EnergyTermsVersion::Current;
};
// The channels of `reader` (as far as it knows them) that carry one of our types, by channel id.
std::vector<RecordedChannel> recorded_channels(const mcap::IndexedReader& reader);

// ---------------------------------------------------------------------------------------------
// Steps

struct RecordingOptions {
  std::string ns;  // ROS namespace of the topics; empty: the only one of each type in the file
  // The per-step topics read (BodyStates, SpringStates, Energy; others are refused). Empty: all
  // three. Topics not read are not decoded.
  std::vector<msgs::TopicId> read;
  // Per-step topics that must be in the file (a channel of the type, in the namespace).
  std::vector<msgs::TopicId> require;
  // false: a recording without a scene description (or with one this build cannot decode) is
  // read too, and scene() is null.
  bool require_scene = true;
  bool verify_crc = false;  // check the data section CRC on open (reads the whole file once)
};

// One recorded step. A message pointer is null when the topic is not read, not recorded, or has
// no message for this step (lost by a live recorder, or a recording cut short). The messages are
// checked against the scene description when there is one: as many bodies, springs, and gravity
// and spring potentials. Valid during the callback only: the reader reuses their storage.
struct RecordedStep {
  std::uint64_t step = 0;
  const msgs::BodyStatesMessage* body_states = nullptr;
  const msgs::SpringStatesMessage* spring_states = nullptr;
  const msgs::EnergyTermsMessage* energy = nullptr;
  // The log time of each message present (0 for one that is not).
  struct LogTimes {
    mcap::Timestamp body_states = 0, spring_states = 0, energy = 0;
  } log_time;
};

class Recording {
 public:
  // Opens `path`, finds our topics by type and reads the scene description (the first message of
  // its topic in log-time order). Errors name the file and what is wrong: unreadable or corrupt
  // file, several topics of one type (choose a namespace), a schema differing from this build's, a
  // required topic missing, no scene description.
  [[nodiscard]] static Result<std::unique_ptr<Recording>> open(const std::string& path,
                                                               const RecordingOptions& options = {});
  ~Recording();
  Recording(const Recording&) = delete;
  Recording& operator=(const Recording&) = delete;

  const std::string& path() const;
  // The scene description; null only when require_scene was false and the file has none.
  const msgs::SceneMessage* scene() const;
  // The topic name read for `id` ("/rbsim/body_states"); empty when the file has none.
  const std::string& topic(msgs::TopicId id) const;

  // Calls `on_step` for every recorded step in increasing step order, with the messages of the
  // read topics that carry it, until the callback fails (its error is returned). A step is passed
  // on once every read topic has either delivered it or moved past it, so messages are held back
  // only as long as the topics' log times interleave. Fails (naming the file, the topic and the
  // message's log time) on a malformed message, a step that does not increase on its topic (a
  // repeat included), or a message that does not match the scene description. Decoding and
  // joining reuse their storage: once warm, they do not allocate for a recording whose topics
  // interleave no more than they did so far.
  [[nodiscard]] Status read_steps(const std::function<Status(const RecordedStep&)>& on_step);

 private:
  Recording();
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rbsim::log
