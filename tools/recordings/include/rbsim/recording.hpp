// Reading a recording back: the one reader of rbsim's MCAP recordings. Render, plot, export, the
// golden verifier, replay and rbsim check read through it (with RecordStream, record_stream.hpp,
// for check's file-order stream); no other module uses the MCAP readers. It serves every topic:
// rbsim's per-step topics decoded and joined by step (read_steps), and any topic as raw messages
// in log-time order (read_messages). Topics are found by type from msgs::topics(), never by name;
// messages are decoded by this build's typed decoders, so a channel whose schema text differs from
// this build's is refused rather than misread. A message's step is msgs::message_step's, the one
// step rule.
//
// A recording's messages may arrive in any log-time order: a live recording (rbsim record, DDS)
// stamps each message with its arrival time, so the latched scene description can come after the
// first body states and the per-step topics of one step interleave with those of the next. The
// reader reads the scene description first, wherever it is in the file, and joins the per-step
// messages of different topics by the step they carry.
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "rbsim/core.hpp"
#include "rbsim/interfaces.hpp"
#include "rbsim/mcap.hpp"
#include "rbsim/msgs.hpp"

namespace rbsim::recordings {

// ---------------------------------------------------------------------------------------------
// Channels and messages

// A channel of a recording: rbsim's types (found by schema name) and any other.
struct RecordedChannel {
  const mcap::Channel* channel = nullptr;  // points into the recording's channels
  const mcap::Schema* schema = nullptr;    // its schema; null when it has none (or the file lacks it)
  const msgs::TopicSpec* spec = nullptr;   // the rbsim topic whose type it carries; null: another type
  // For one of our types: empty when the channel can be decoded by this build (message encoding
  // "cdr", a "ros2msg" schema whose text equals this build's); otherwise why not, e.g. "its
  // rbsim_msgs/msg/BodyStates schema differs from this build's (recorded by another version?)".
  std::string problem;
  // The layout of an EnergyTerms channel: a recording made before the potential split is read too.
  msgs::EnergyTermsVersion energy_version = msgs::EnergyTermsVersion::Current;
  std::optional<std::uint64_t> message_count;  // from the summary's statistics, when it has them
  std::string_view schema_text() const;        // the schema's data as text ("" without one)
};

// One message as recorded (CDR for rbsim's types). Valid during the callback only.
struct RecordedMessage {
  const RecordedChannel* channel = nullptr;
  const mcap::Message* message = nullptr;  // log and publish time, sequence, data
  const std::string& topic() const { return channel->channel->topic; }
  std::span<const std::byte> cdr() const { return message->data; }
};

// Which messages read_messages() passes on: by topic name (empty: every topic) and log time.
struct MessageFilter {
  std::vector<std::string> topics;
  mcap::Timestamp start = 0;                    // log time >= start
  mcap::Timestamp end = mcap::kMaxTime;         // log time < end
  std::vector<std::uint64_t> skip_chunks = {};  // chunks (chunk_indexes()' start offsets) not to read
};

// Called for each message in log-time order; returns false to stop reading (not an error).
using MessageCallback = std::function<bool(const RecordedMessage&)>;

// ---------------------------------------------------------------------------------------------
// Steps

struct RecordingOptions {
  std::string ns;  // ROS namespace of the topics; empty: the only one of each type in the file
  // The per-step topics read_steps() joins (BodyStates, SpringStates, Energy; others are refused).
  // Empty: all three. Topics not read are not decoded.
  std::vector<msgs::TopicId> read;
  // false: no per-step topic is looked for (read_steps() passes nothing): the recording is read as
  // raw messages only, whatever types its channels carry.
  bool steps = true;
  // Per-step topics that must be in the file (a channel of the type, in the namespace).
  std::vector<msgs::TopicId> require;
  // false: the scene description is not looked for, and scene() is null.
  bool scene = true;
  // false: a recording without a scene description (or with one this build cannot decode) is
  // read too, and scene() is null.
  bool require_scene = true;
  bool verify_crc = false;  // check the data section CRC on open (reads the whole file once)
};
// The options of a reader of raw messages only (rbsim check, replay, log cat): neither steps nor
// a scene description are looked for, so a file of any types opens.
inline RecordingOptions raw_options() {
  RecordingOptions o;
  o.steps = false;
  o.scene = false;
  return o;
}

// One recorded step. A message pointer is null when the topic is not read, not recorded, or has
// no message for this step (lost by a live recorder, or a recording cut short). The messages are
// checked against the step's scene description when there is one: as many bodies, springs, and
// gravity and spring potentials. Valid during the callback only: the reader reuses their storage.
//
// Epochs: a world whose bodies change (a spawn, a delete, rbsim/control.hpp) is recorded as a new
// scene description at the step of the change, followed by that step's per-step messages again
// with the new arrays. Each scene description after the first (in log-time order) starts an epoch
// at its step; a step's messages are those of the last epoch that starts at or before it, and of a
// step recorded again after a change, the last in log-time order. The arrays of each message are
// in its epoch's order (BodyStates' ids and the scene description's bodies index for index).
//
// Segments: where the steps start again at 0 (a reset, a world loaded: rbsim/control.hpp), the
// recording holds the steps before and after one after the other, each from its own step 0: a
// segment each. A restart is recorded as a scene description of step 0 followed by step 0's
// per-step messages again, so on every topic a step 0 recorded again, or a step that goes back,
// starts the next segment. Steps are passed on in (segment, step) order, which is the order of the
// session; a step's epoch is the last whose description starts at or before it in that order. A
// step 0 recorded again before the world stepped (a spawn at step 0, a world loaded at step 0) is,
// as any step recorded again at a change, taken from its last recording: segments are numbered
// as passed on, without those that held only a replaced step 0.
struct RecordedStep {
  std::uint64_t step = 0;
  std::uint32_t segment = 0;  // 0, then one more each time the steps start again
  // The scene description of the step's epoch (scene() for the first); null without one.
  const msgs::SceneMessage* scene = nullptr;
  std::uint32_t epoch = 0;  // 0, then one more at each later scene description
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
  // The first scene description (the first epoch's); null only when require_scene was false and
  // the file has none. A later one, after bodies came or went, is a step's (RecordedStep::scene).
  const msgs::SceneMessage* scene() const;
  // The topic name read for `id` ("/rbsim/body_states"); empty when the file has none.
  const std::string& topic(msgs::TopicId id) const;

  // Calls `on_step` for every recorded step in (segment, step) order, with the messages of the
  // read topics that carry it, until the callback fails (its error is returned). A step is passed
  // on once every read topic has moved past it (or the file ends), so messages are held back only
  // as long as the topics' log times interleave, and one step more (it may be recorded again). Fails (naming
  // the file, the topic and the message's log time) on a malformed message, a step recorded twice on
  // its topic (unless a scene description came between: an epoch), a scene description whose step
  // goes back but to 0, or a message that does not match its step's scene description. Decoding and
  // joining reuse their storage: once warm, they do not allocate for a recording whose topics
  // interleave no more than they did so far. `also` names other topics whose raw messages go to
  // `on_message` in the same pass (log-time order), so a reader of both reads the file once.
  [[nodiscard]] Status read_steps(const std::function<Status(const RecordedStep&)>& on_step,
                                  const MessageFilter& also = {}, const MessageCallback& on_message = {});

  // Every channel of the file, rbsim's and others', in the order they became known: the summary's
  // by id, then any that a read found in the data section (pointers to them stay valid).
  const std::deque<RecordedChannel>& channels() const;
  const mcap::Header& header() const;
  // True when the summary lists every channel that has messages (every chunk's message index
  // names only channels it lists, as rbsim writes them): a topic not listed has no messages.
  bool lists_every_channel() const;
  // The log time of the last message, from the summary (statistics, chunk indexes), if it says.
  std::optional<mcap::Timestamp> last_log_time() const;

  // The summary's chunk indexes (none in a file without them or in a bag of several files), and one chunk as
  // stored, still compressed, with its message indexes; with verify its CRC is checked (a decompression; a
  // caller may instead check it with mcap::decompress_chunk elsewhere, as log filter does on a
  // second thread). For a tool that copies whole chunks (through mcap::Writer::copy_chunk).
  const std::vector<mcap::ChunkIndex>& chunk_indexes() const;
  struct RawChunk {
    mcap::Chunk chunk;
    std::vector<mcap::MessageIndex> indexes;
  };
  [[nodiscard]] Result<RawChunk> read_chunk(const mcap::ChunkIndex& index, bool verify = true);

  // The raw messages `filter` picks, in log-time order, until `on_message` returns false. Fails
  // on an unreadable or corrupt file (naming it and what is wrong).
  [[nodiscard]] Status read_messages(const MessageFilter& filter, const MessageCallback& on_message);

 private:
  Recording();
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The commands a steered session recorded (rbsim_msgs/msg/Command on topic(TopicId::Commands)), in
// sequence order, each once; none when the file has no such topic. The node numbers its commands
// from 0 without gaps, so a missing number is an error naming it (a recorder that joined late or
// lost some: the file is not the whole session), as is a message that does not decode.
[[nodiscard]] Result<std::vector<msgs::CommandMessage>> read_commands(Recording& recording);

}  // namespace rbsim::recordings
