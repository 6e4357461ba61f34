// The middleware seam, what rmw.h is to ROS 2: participants (one ROS 2 node each), publishers and
// subscriptions of raw CDR on ROS topics with QoS, samples with their writer and its offered QoS,
// and waiting on several subscriptions. No middleware type appears here: each class is a thin
// handle on a backend's implementation (rbsim/middleware_backend.hpp), created by the backend's
// participant (node/dds: create_dds_participant; node/memory: create_memory_participant) and
// reached through it. Services are in rbsim/service.hpp.
//
// Payloads are CDR with the 4-byte encapsulation header, the exact bytes rbsim_msgs encodes: the
// same bytes go to the network, to MCAP and back.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "rbsim/msgs.hpp"
#include "rbsim/node_types.hpp"
#include "rbsim/status.hpp"

namespace rbsim::node {

// A backend participant's domain argument for "ROS_DOMAIN_ID, else 0".
inline constexpr std::uint32_t kDomainFromEnvironment = UINT32_MAX;

// A node's name as rcl splits a fully qualified name: "/a/b/sim" is node "sim" in namespace
// "/a/b"; "/rbsim" is node "rbsim" in the root namespace "/".
struct NodeName {
  std::string ns = "/";
  std::string name = "rbsim";
  std::string fully_qualified() const;  // "/a/b/sim"
  std::string logger_name() const;      // "a.b.sim", as rcl names the node's logger (rosout's name field)
};

class ParticipantImpl;  // rbsim/middleware_backend.hpp
class PublisherImpl;
class SubscriptionImpl;
class WaitSetImpl;

// One node on a middleware. Publishers, subscriptions, wait sets and services are created from
// it; it goes last (a backend may keep what they need alive, but callers should not rely on it).
class Participant {
 public:
  explicit Participant(std::unique_ptr<ParticipantImpl> impl);
  Participant(Participant&&) noexcept;
  Participant& operator=(Participant&&) = delete;
  ~Participant();
  // How it was configured, for the start line: e.g. "domain 7 (LOCALHOST)".
  const std::string& description() const;
  const NodeName& node() const;
  // The types of the node's endpoints while they live (rbsim/node_types.hpp): what its
  // ~/get_type_description answers for.
  const std::shared_ptr<NodeTypeCache>& types() const { return types_; }
  ParticipantImpl& impl() const { return *impl_; }  // for backends

 private:
  std::unique_ptr<ParticipantImpl> impl_;
  std::shared_ptr<NodeTypeCache> types_ = std::make_shared<NodeTypeCache>();
};

using QosSpec = msgs::OfferedQos;
// The QoS rbsim's writers use (msgs::offered_qos: what recordings say they offered).
inline QosSpec qos_for(const msgs::TopicSpec& spec, std::int32_t keep_last = 0) {
  return msgs::offered_qos(spec, keep_last);
}

// A topic outside msgs::topics() by its ROS names: "/rosout", "rcl_interfaces/msg/Log".
struct RawTopic {
  std::string ros_name;
  std::string ros_type;
};
// What an endpoint carries besides its topic and QoS.
struct EndpointOptions {
  // REP 2011's "RIHS01_<64 hex>" of the endpoint's type, where the backend announces one; empty:
  // the backend computes it from the topic's type (msgs::type_hash).
  std::string type_hash;
  std::int64_t lifespan_ns = 0;  // > 0: samples expire that long after they were written (/rosout)
  bool in_graph = true;          // listed among the node's endpoints on the ROS 2 graph
};

// Publishes pre-encoded CDR messages on one topic.
class Publisher {
 public:
  static Result<Publisher> create(const Participant& participant, const msgs::TopicSpec& spec,
                                  std::string_view ros_topic, const QosSpec& qos,
                                  const EndpointOptions& options = {});
  static Result<Publisher> create(const Participant& participant, const RawTopic& topic, const QosSpec& qos,
                                  const EndpointOptions& options = {});
  Publisher(std::unique_ptr<PublisherImpl> impl, std::string ros_topic);  // for backends
  Publisher(Publisher&&) noexcept;
  Publisher& operator=(Publisher&&) = delete;
  ~Publisher();
  // Blocks while a reliable subscriber's window is full, up to 30 s in all; when `stop` turns
  // true meanwhile, gives up on this sample with ErrorCode::Cancelled.
  [[nodiscard]] Status publish(std::span<const std::byte> cdr, bool (*stop)() = nullptr);
  std::int32_t matched() const;  // subscriptions currently matched
  // The one wait for subscribers (rbsim node's and rbsim replay's --wait-for-subscribers): until
  // `count` subscriptions match; false when `stop` (if any, looked at every 20 ms) turned true.
  bool wait_for_subscribers(std::int32_t count, bool (*stop)()) const;
  // Waits until every matched reliable reader acknowledged everything written (bounded; about a
  // second once `stop` is true).
  [[nodiscard]] Status flush(double timeout_s, bool (*stop)() = nullptr);
  const std::string& ros_topic() const { return ros_topic_; }
  PublisherImpl& impl() const { return *impl_; }  // for backends

 private:
  std::unique_ptr<PublisherImpl> impl_;
  std::string ros_topic_;
  TypeRegistration type_;  // a node's endpoint: its type in the node's cache
};

// A sample's storage lent by the backend (no copy): released when the loan goes. Move-only.
class Loan {
 public:
  Loan() = default;
  Loan(void* held, void (*release)(void*)) noexcept : held_(held), release_(release) {}
  Loan(Loan&& o) noexcept : held_(std::exchange(o.held_, nullptr)), release_(o.release_) {}
  Loan& operator=(Loan&& o) noexcept {
    if (this != &o) {
      reset();
      held_ = std::exchange(o.held_, nullptr);
      release_ = o.release_;
    }
    return *this;
  }
  Loan(const Loan&) = delete;
  Loan& operator=(const Loan&) = delete;
  ~Loan() { reset(); }
  void reset() noexcept {
    if (held_ != nullptr) release_(std::exchange(held_, nullptr));
  }
  void* get() const { return held_; }
  explicit operator bool() const { return held_ != nullptr; }

 private:
  void* held_ = nullptr;
  void (*release_)(void*) = nullptr;
};

struct Received {
  // The sample's CDR bytes, borrowed from the middleware without a copy: valid while `held` keeps
  // them (a move keeps them valid; the next take into this Received replaces them).
  std::span<const std::byte> cdr;
  Loan held;
  std::int64_t source_time_ns = 0;
  std::array<std::uint8_t, 16> writer{};  // the sending writer's id (stable when it is rediscovered)
  msgs::OfferedQos offered;               // what that writer offers (history, depth, durability)
};

// Takes raw CDR samples from one topic.
class Subscription {
 public:
  static Result<Subscription> create(const Participant& participant, const msgs::TopicSpec& spec,
                                     std::string_view ros_topic, const QosSpec& qos,
                                     const EndpointOptions& options = {});
  // A topic outside msgs::topics(): spec() is not available.
  static Result<Subscription> create(const Participant& participant, const RawTopic& topic,
                                     const QosSpec& qos, const EndpointOptions& options = {});
  Subscription(std::unique_ptr<SubscriptionImpl> impl, std::string ros_topic,
               const msgs::TopicSpec* spec);  // for backends
  Subscription(Subscription&&) noexcept;
  Subscription& operator=(Subscription&&) = delete;
  ~Subscription();
  // Takes one sample if there is one.
  bool take(Received& out);
  std::uint64_t lost() const;    // samples the middleware reports lost or rejected
  std::int32_t matched() const;  // publications currently matched
  const std::string& ros_topic() const { return ros_topic_; }
  const msgs::TopicSpec& spec() const;               // only for one created with a TopicSpec
  SubscriptionImpl& impl() const { return *impl_; }  // for backends

 private:
  std::unique_ptr<SubscriptionImpl> impl_;
  std::string ros_topic_;
  const msgs::TopicSpec* spec_ = nullptr;
  TypeRegistration type_;  // a node's endpoint: its type in the node's cache
};

// Waits for samples on several subscriptions at once: the loop of the recorder and of the relay,
// which take from every subscription once any has something.
class WaitSet {
 public:
  static Result<WaitSet> create(const Participant& participant);
  WaitSet();
  explicit WaitSet(std::unique_ptr<WaitSetImpl> impl);  // for backends
  WaitSet(WaitSet&& other) noexcept;
  WaitSet& operator=(WaitSet&& other) noexcept;
  ~WaitSet();
  // The subscription must outlive the wait set's use of it (a move of the handle is fine).
  void attach(const Subscription& subscription);
  // Waits up to `timeout_ns` until an attached subscription has samples; returns how many have.
  Result<std::int32_t> wait(std::int64_t timeout_ns);

 private:
  std::unique_ptr<WaitSetImpl> impl_;
};

}  // namespace rbsim::node
