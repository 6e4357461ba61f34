// DDS with ROS 2 conventions on Eclipse Cyclone DDS: participants, and publishers and
// subscriptions of raw CDR on rbsim's topics (topics "rt/<namespace>/<name>", types
// "pkg::msg::dds_::Name_", CDR with the 4-byte encapsulation header), so a ROS 2 system using
// rmw_cyclonedds_cpp sees them. Payloads are the exact bytes rbsim_msgs encodes: the same bytes
// go to DDS, to MCAP and back.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "rbsim/core.hpp"
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

// Looks up a TopicSpec by ROS topic suffix ("body_states") or full name ("/rbsim/body_states").
const msgs::TopicSpec* find_topic(std::string_view name, std::string_view ns);

}  // namespace rbsim::node
