// DDS with ROS 2 conventions on Eclipse Cyclone DDS: participants, and publishers and
// subscriptions of raw CDR on rbsim's topics (topics "rt/<namespace>/<name>", types
// "pkg::msg::dds_::Name_", CDR with the 4-byte encapsulation header), so a ROS 2 system using
// rmw_cyclonedds_cpp sees them. Payloads are the exact bytes rbsim_msgs encodes: the same bytes
// go to DDS, to MCAP and back.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "rbsim/core.hpp"
#include "rbsim/msgs.hpp"
#include "rbsim/ros_env.hpp"

struct ddsi_sertype;  // Cyclone DDS
struct ddsi_serdata;

namespace rbsim::node {

// Participant::create's domain argument for "ROS_DOMAIN_ID, else 0".
inline constexpr std::uint32_t kDomainFromEnvironment = UINT32_MAX;

// A DDS participant, configured by ROS 2's environment variables (rbsim/ros_env.hpp): by default
// (ROS_AUTOMATIC_DISCOVERY_RANGE unset or LOCALHOST, no ROS_STATIC_PEERS) the domain runs on
// rbsim's loopback configuration (127.0.0.1 only, no multicast, ParticipantIndex auto); with
// CYCLONEDDS_URI set, on whatever that configuration says. Warnings about variables that are
// ignored go to stderr.
class Participant {
 public:
  // `domain`: the explicit id (--domain), or kDomainFromEnvironment.
  static Result<Participant> create(std::uint32_t domain = kDomainFromEnvironment);
  Participant(Participant&& other) noexcept;
  Participant& operator=(Participant&&) = delete;
  ~Participant();
  std::int32_t handle() const { return handle_; }
  std::uint32_t domain() const { return domain_; }
  // How it was configured, e.g. "domain 7 (LOCALHOST)" (DdsSettings::describe).
  const std::string& description() const { return description_; }

 private:
  Participant(std::int32_t handle, std::uint32_t domain, std::string description)
      : handle_(handle), domain_(domain), description_(std::move(description)) {}
  std::int32_t handle_ = 0;
  std::uint32_t domain_ = 0;
  std::string description_;
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
  // Blocks while a reliable subscriber's window is full, up to 30 s in all; when `stop` turns
  // true meanwhile, gives up on this sample with ErrorCode::Cancelled.
  [[nodiscard]] Status publish(std::span<const std::byte> cdr, bool (*stop)() = nullptr);
  std::int32_t matched() const;  // subscriptions currently matched
  // Waits until every matched reliable reader acknowledged everything written (bounded; about a
  // second once `stop` is true).
  [[nodiscard]] Status flush(double timeout_s, bool (*stop)() = nullptr);
  std::int32_t writer() const { return writer_; }
  const std::string& ros_topic() const { return ros_topic_; }

 private:
  Publisher() = default;
  std::int32_t writer_ = 0, topic_ = 0;
  const ddsi_sertype* sertype_ = nullptr;  // the writer's (raw CDR) type, owned by the topic
  std::string ros_topic_;
};

// Takes raw CDR samples from one topic.
struct SerdataUnref {
  void operator()(ddsi_serdata* d) const;
};
struct Received {
  // The sample's CDR bytes, borrowed from DDS without a copy: valid while `held` keeps them (a
  // move keeps them valid; the next take into this Received replaces them).
  std::span<const std::byte> cdr;
  std::unique_ptr<ddsi_serdata, SerdataUnref> held;
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
  std::uint64_t lost() const;    // samples DDS reports lost or rejected
  std::int32_t matched() const;  // publications currently matched
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

// Looks up a TopicSpec by ROS topic suffix ("body_states") or full name ("/rbsim/body_states").
const msgs::TopicSpec* find_topic(std::string_view name, std::string_view ns);

}  // namespace rbsim::node
