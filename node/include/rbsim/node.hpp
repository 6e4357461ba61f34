// rbsim over DDS: the node that streams a running scene, the recorder and the replay, on
// Eclipse Cyclone DDS with ROS 2 conventions (topics "rt/<namespace>/<name>", types
// "pkg::msg::dds_::Name_", CDR with the 4-byte encapsulation header), so a ROS 2 system using
// rmw_cyclonedds_cpp sees the topics. Payloads are the exact bytes rbsim_msgs encodes: the same
// bytes go to DDS, to MCAP and back.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "rbsim/io.hpp"
#include "rbsim/mcap.hpp"
#include "rbsim/msgs.hpp"

namespace rbsim::node {

// Domain ids that map onto valid UDP ports with the default port mapping.
inline constexpr std::uint32_t kMaxDomainId = 232;

// A DDS participant. Without CYCLONEDDS_URI in the environment the domain runs on rbsim's
// loopback configuration (127.0.0.1 only, no multicast, ParticipantIndex auto); with it, on
// whatever that configuration says.
class Participant {
 public:
  static Result<Participant> create(std::uint32_t domain);
  Participant(Participant&& other) noexcept;
  Participant& operator=(Participant&&) = delete;
  ~Participant();
  std::int32_t handle() const { return handle_; }
  std::uint32_t domain() const { return domain_; }

 private:
  Participant(std::int32_t handle, std::uint32_t domain) : handle_(handle), domain_(domain) {}
  std::int32_t handle_ = 0;
  std::uint32_t domain_ = 0;
};

// The loopback configuration compiled into rbsim (node/config/cyclonedds-loopback.xml).
std::string_view loopback_config();

using QosSpec = msgs::OfferedQos;
// The QoS rbsim's writers use (msgs::offered_qos: what recordings say they offered).
inline QosSpec qos_for(const msgs::TopicSpec& spec, std::int32_t keep_last = 0) {
  return msgs::offered_qos(spec, keep_last);
}

// Publishes pre-encoded CDR messages on one topic.
class Publisher {
 public:
  static Result<Publisher> create(const Participant& participant, const msgs::TopicSpec& spec,
                                  std::string_view ros_topic, const QosSpec& qos);
  Publisher(Publisher&&) noexcept;
  Publisher& operator=(Publisher&&) = delete;
  ~Publisher();
  [[nodiscard]] Status publish(std::span<const std::byte> cdr);
  std::int32_t matched() const;  // subscriptions currently matched
  // Waits until every matched reliable reader acknowledged everything written (bounded).
  [[nodiscard]] Status flush(double timeout_s);
  std::int32_t writer() const { return writer_; }
  const std::string& ros_topic() const { return ros_topic_; }

 private:
  Publisher() = default;
  std::int32_t writer_ = 0, topic_ = 0;
  std::string ros_topic_;
};

// Takes raw CDR samples from one topic.
struct Received {
  std::vector<std::byte> cdr;
  std::int64_t source_time_ns = 0;
  std::array<std::uint8_t, 16> writer{};  // the sending writer's GUID (stable when it is rediscovered)
  msgs::OfferedQos offered;               // what that writer offers (history, depth, durability)
};
class Subscription {
 public:
  static Result<Subscription> create(const Participant& participant, const msgs::TopicSpec& spec,
                                     std::string_view ros_topic, const QosSpec& qos);
  Subscription(Subscription&&) noexcept;
  Subscription& operator=(Subscription&&) = delete;
  ~Subscription();
  // Takes one sample if there is one.
  bool take(Received& out);
  std::int32_t reader() const { return reader_; }
  std::uint64_t lost() const;  // samples DDS reports lost or rejected
  const std::string& ros_topic() const { return ros_topic_; }
  const msgs::TopicSpec& spec() const { return *spec_; }

 private:
  Subscription() = default;
  std::int32_t reader_ = 0, topic_ = 0;
  std::string ros_topic_;
  const msgs::TopicSpec* spec_ = nullptr;
  struct Writer {
    std::uint64_t handle = 0;  // DDS instance handle of the matched publication
    std::array<std::uint8_t, 16> guid{};
    msgs::OfferedQos offered;
  };
  std::vector<Writer> writers_;
};

// ---------------------------------------------------------------------------------------------
// The node: a Sink that publishes every topic of a step over DDS.

struct NodeOptions {
  std::uint32_t domain = 0;
  std::string ns = "rbsim";
  double rate = 1.0;               // real-time factor; 0: as fast as possible
  std::int64_t publish_every = 1;  // publish every k-th step
  std::int32_t keep_last = 0;      // per-step writers keep last N instead of keep all (0)
};
// Publishes the scene description at begin() and the per-step topics on every k-th step,
// pacing steps to wall time by `rate`.
class DdsSink final : public Sink {
 public:
  static Result<std::unique_ptr<DdsSink>> create(const Participant& participant, const NodeOptions& options);
  Status begin(const Scene& scene, const World& world) override;
  Status write(const World& world) override;
  // Waits (bounded) until subscribers acknowledged everything, so nothing in flight is lost
  // when the node exits.
  Status finish() override;
  // Waits until `count` subscriptions match the body-state topic; false when `stop` turned true.
  bool wait_for_subscribers(std::int32_t count, bool (*stop)());
  // Restarts the pacing clock (e.g. when --loop starts the scene again).
  void restart_clock();
  std::uint64_t published() const { return published_; }

 private:
  DdsSink() = default;
  Status publish(msgs::TopicId id, const World& world);
  NodeOptions options_;
  std::vector<std::optional<Publisher>> publishers_;  // by TopicId
  std::unique_ptr<msgs::Encoder> encoder_;
  msgs::Bytes buffer_;
  std::int64_t start_ns_ = 0;  // monotonic clock at the paced step
  std::int64_t start_step_ = 0;
  std::uint64_t published_ = 0;
};

// ---------------------------------------------------------------------------------------------
// The recorder: subscribes to rbsim topics and writes the exact CDR payloads to MCAP (rosbag2
// layout), log_time = receive time, publish_time = the sample's source timestamp (both ns since
// the Unix epoch). Chunks are flushed as they fill, so a killed recorder leaves a file
// `rbsim log recover` repairs.
//
// Lost messages are what DDS reports lost or rejected plus the gaps the recorder sees in the
// steps of each per-step topic: every per-step message carries its simulated time (header stamp,
// or the clock), the scene description gives dt, so each message names its step; the node
// publishes every k-th step, so within one run of the scene (a --loop restarts it) the steps
// received on a topic are first, first + k, ..., last, and the ones missing from that sequence
// were lost, e.g. while a link was down for longer than the DDS lease and the reader was
// dropped (messages that DDS itself never reports). k is the smallest step difference seen.

struct RecorderOptions {
  std::string path;
  std::string ns = "rbsim";
  std::vector<std::string> topics;  // names ("body_states" or "/rbsim/body_states"); empty: all
  mcap::Compression compression = mcap::Compression::Zstd;
  int compression_level = 0;  // 0: the codec's default
  std::uint64_t chunk_size = 1 << 20;
  std::uint64_t max_messages = 0;  // 0: no limit
};

class Recorder {
 public:
  static Result<std::unique_ptr<Recorder>> create(const Participant& participant,
                                                  const RecorderOptions& options);
  ~Recorder();
  // Waits up to `timeout_ns` for data and records everything available; true if anything came.
  Result<bool> poll(std::int64_t timeout_ns);
  [[nodiscard]] Status close();  // finishes a valid, indexed file
  std::uint64_t received() const { return received_; }
  struct TopicCount {
    std::string topic;
    std::uint64_t received = 0, lost = 0;  // lost: reported by DDS plus gaps in the steps
    std::uint64_t duplicates = 0;          // samples delivered again, not recorded twice
  };
  std::vector<TopicCount> counts() const;

 private:
  Recorder() = default;
  // Steps received on one per-step topic since the scene (re)started, as simulated times in ns
  // (converted with dt once the scene description is known).
  struct Gaps {
    std::int64_t first = -1, last = -1, stride = 0;  // ns; stride: smallest difference seen
    std::uint64_t count = 0;                         // messages in this run of the scene
    std::uint64_t lost_before = 0;                   // in earlier runs (--loop)
    void add(std::int64_t stamp_ns, double dt);
    std::uint64_t lost(double dt) const;
  };
  struct Topic {
    Subscription subscription;
    std::uint16_t channel;  // 0 until the first sample: its writer's QoS goes into the channel
    std::uint32_t received;
    Gaps gaps;
    // Per writer, the newest source timestamp recorded. A sample not newer than that is one
    // delivered again: after a reconnection DDS can resend what a reader already had (seen when
    // a link came back after the lease expired), and a log must hold each message once.
    std::vector<std::pair<std::array<std::uint8_t, 16>, std::int64_t>> newest{};
    std::uint64_t duplicates = 0;
  };
  RecorderOptions options_;
  mcap::Writer writer_;
  std::int32_t waitset_ = 0;
  std::vector<Topic> topics_;
  std::uint64_t received_ = 0;
  double dt_ = 0.0;  // from the scene description; 0 until it arrives
};

// Looks up a TopicSpec by ROS topic suffix ("body_states") or full name ("/rbsim/body_states").
const msgs::TopicSpec* find_topic(std::string_view name, std::string_view ns);

}  // namespace rbsim::node

// ---------------------------------------------------------------------------------------------
// The replay: an MCAP recording (rbsim run --record or rbsim record) republished over DDS with
// its recorded timing. Every channel whose schema names one of our types (msgs::topics()) and
// whose messages are CDR gets a publisher with that topic's QoS; messages go out in log-time
// order, paced by their log-time differences divided by `rate`.

namespace rbsim::node {

struct ReplayOptions {
  std::string path;
  double rate = 1.0;  // real-time factor on log time; 0: as fast as possible
  std::vector<std::string>
      topics;  // recorded names ("/rbsim/body_states") or suffixes ("body_states"); empty: all
  double start_offset =
      0.0;             // seconds of log time skipped at the start (the scene description is still sent)
  bool clock = false;  // publish rosgraph_msgs/Clock on /clock with each message's log time
                       // (recorded /clock messages are then not replayed)
  std::optional<std::string> ns;  // republish under /<ns>/<name> instead of the recorded names
  std::int32_t keep_last = 0;     // per-step writers keep last N instead of keep all (0)
};

class Replay {
 public:
  // Opens the recording and creates the publishers. Errors: unreadable or non-MCAP input, no rbsim
  // topics in the log, --topics names the log does not have.
  static Result<std::unique_ptr<Replay>> open(const Participant& participant, const ReplayOptions& options);
  ~Replay();

  struct Output {
    std::string
        recorded;       // channel topic in the log ("/rbsim/body_states"), empty for the synthesized /clock
    std::string topic;  // topic published
    std::uint64_t messages = 0;  // messages of the channel in the log (0 when unknown)
  };
  const std::vector<Output>& outputs() const { return outputs_; }
  std::uint64_t first_log_time() const { return first_log_time_; }
  std::uint64_t last_log_time() const { return last_log_time_; }

  // Waits until `count` subscriptions match the body-state publisher (or, without body states,
  // the first one); false when `stop` turned true.
  bool wait_for_subscribers(std::int32_t count, bool (*stop)());
  // Plays the log once from the start offset; Ok(false) when `stop` turned true on the way.
  Result<bool> play(bool (*stop)());
  // Waits (bounded) until the subscribers acknowledged everything published, so nothing in
  // flight is lost when the replay exits.
  [[nodiscard]] Status finish(double timeout_s = 30.0);
  std::uint64_t published() const { return published_; }
  // Channels left out (not CDR, or a definition that differs from this build's).
  const std::vector<std::string>& warnings() const { return warnings_; }

 private:
  Replay() = default;
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::vector<Output> outputs_;
  std::vector<std::string> warnings_;
  std::uint64_t first_log_time_ = 0, last_log_time_ = 0;
  std::uint64_t published_ = 0;
};

}  // namespace rbsim::node
