// DDS with ROS 2 conventions on Eclipse Cyclone DDS: participants, and publishers and
// subscriptions of raw CDR on rbsim's topics (topics "rt/<namespace>/<name>", types
// "pkg::msg::dds_::Name_", CDR with the 4-byte encapsulation header), so a ROS 2 system using
// rmw_cyclonedds_cpp sees them. Payloads are the exact bytes rbsim_msgs encodes: the same bytes
// go to DDS, to MCAP and back.
//
// Each participant is one ROS 2 node on the graph (as rmw_cyclonedds_cpp makes them): its
// USER_DATA says "enclave=/;", and it publishes ros_discovery_info listing the node with every
// reader and writer the wrappers below create (rbsim/graph.hpp), in the GID format ROS_DISTRO
// selects (rbsim/ros_env.hpp).
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

class Graph;  // rbsim/graph.hpp

// A DDS participant, configured by ROS 2's environment variables (rbsim/ros_env.hpp): by default
// (ROS_AUTOMATIC_DISCOVERY_RANGE unset or LOCALHOST, no ROS_STATIC_PEERS) the domain runs on
// rbsim's loopback configuration (127.0.0.1 only, no multicast, ParticipantIndex auto); with
// CYCLONEDDS_URI set, on whatever that configuration says. Warnings about variables that are
// ignored go to stderr.
class Participant {
 public:
  // `domain`: the explicit id (--domain), or kDomainFromEnvironment; `node`: the node it is.
  static Result<Participant> create(std::uint32_t domain = kDomainFromEnvironment, const NodeName& node = {});
  Participant(Participant&& other) noexcept;
  Participant& operator=(Participant&&) = delete;
  ~Participant();
  std::int32_t handle() const { return handle_; }
  std::uint32_t domain() const { return domain_; }
  // How it was configured, e.g. "domain 7 (LOCALHOST)" (DdsSettings::describe).
  const std::string& description() const { return description_; }
  const NodeName& node() const { return node_; }
  RosDistro distro() const { return distro_; }
  // The node's graph entry: endpoints created outside Publisher and Subscription (a service's
  // request reader and reply writer) register there. Null only while the participant is created.
  Graph* graph() const { return graph_.get(); }
  std::shared_ptr<Graph> shared_graph() const { return graph_; }

 private:
  Participant(std::int32_t handle, std::uint32_t domain, std::string description, NodeName node,
              RosDistro distro)
      : handle_(handle),
        domain_(domain),
        description_(std::move(description)),
        node_(std::move(node)),
        distro_(distro) {}
  std::int32_t handle_ = 0;
  std::uint32_t domain_ = 0;
  std::string description_;
  NodeName node_;
  RosDistro distro_ = RosDistro::Jazzy;
  std::shared_ptr<Graph> graph_;
};

// The loopback configuration compiled into rbsim (node/config/cyclonedds-loopback.xml).
std::string_view loopback_config();

using QosSpec = msgs::OfferedQos;
// The QoS rbsim's writers use (msgs::offered_qos: what recordings say they offered).
inline QosSpec qos_for(const msgs::TopicSpec& spec, std::int32_t keep_last = 0) {
  return msgs::offered_qos(spec, keep_last);
}

// A topic by its DDS names, for topics outside msgs::topics() (ros_discovery_info, /rosout).
struct RawTopic {
  std::string dds_name;  // "ros_discovery_info", "rt/rosout"
  std::string dds_type;  // "rcl_interfaces::msg::dds_::Log_"
  // "rcl_interfaces/msg/Log": the endpoints' USER_DATA carries its REP 2011 type hash
  // (msgs::type_hash) unless EndpointOptions::type_hash says otherwise; empty: no hash.
  std::string ros_type;
};
// What an endpoint carries besides its topic and QoS.
struct EndpointOptions {
  // REP 2011's "RIHS01_<64 hex>" of the endpoint's type: its USER_DATA then says
  // "typehash=<it>;" as rmw_cyclonedds_cpp writes it, except on Humble (no type hashes). Empty:
  // USER_DATA is empty, as rmw writes it for a type without a hash.
  std::string type_hash;
  std::int64_t lifespan_ns = 0;  // > 0: samples expire that long after they were written (/rosout)
  bool in_graph = true;          // listed in ros_discovery_info (not its own writer, as in rmw)
};

// Publishes pre-encoded CDR messages on one topic.
class Publisher {
 public:
  static Result<Publisher> create(const Participant& participant, const msgs::TopicSpec& spec,
                                  std::string_view ros_topic, const QosSpec& qos,
                                  const EndpointOptions& options = {});
  static Result<Publisher> create(const Participant& participant, const RawTopic& topic, const QosSpec& qos,
                                  const EndpointOptions& options = {});
  Publisher(Publisher&&) noexcept;
  Publisher& operator=(Publisher&&) = delete;
  ~Publisher();
  // Blocks while a reliable subscriber's window is full, up to 30 s in all; when `stop` turns
  // true meanwhile, gives up on this sample with ErrorCode::Cancelled.
  [[nodiscard]] Status publish(std::span<const std::byte> cdr, bool (*stop)() = nullptr);
  std::int32_t matched() const;  // subscriptions currently matched
  // The one wait for subscribers (rbsim node's and rbsim replay's --wait-for-subscribers): until
  // `count` subscriptions match, polling every 20 ms; false when `stop` (if any) turned true.
  bool wait_for_subscribers(std::int32_t count, bool (*stop)()) const;
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
  std::weak_ptr<Graph> graph_;  // where it is listed (gone with the participant: nothing to unlist)
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
                                     std::string_view ros_topic, const QosSpec& qos,
                                     const EndpointOptions& options = {});
  // A topic outside msgs::topics() (a service's requests): spec() is not available.
  static Result<Subscription> create(const Participant& participant, const RawTopic& topic,
                                     const QosSpec& qos, const EndpointOptions& options = {});
  Subscription(Subscription&&) noexcept;
  Subscription& operator=(Subscription&&) = delete;
  ~Subscription();
  // Takes one sample if there is one.
  bool take(Received& out);
  std::int32_t reader() const { return reader_; }
  std::uint64_t lost() const;    // samples DDS reports lost or rejected
  std::int32_t matched() const;  // publications currently matched
  const std::string& ros_topic() const { return ros_topic_; }
  const msgs::TopicSpec& spec() const;  // only for one created with a TopicSpec

 private:
  Subscription() = default;
  std::int32_t reader_ = 0, topic_ = 0;
  std::string ros_topic_;
  const msgs::TopicSpec* spec_ = nullptr;
  QosSpec q_;  // what it asked for: a writer's offer when discovery no longer knows it (no spec)
  std::weak_ptr<Graph> graph_;
  struct Writer {
    std::uint64_t handle = 0;  // DDS instance handle of the matched publication
    std::array<std::uint8_t, 16> guid{};
    msgs::OfferedQos offered;
  };
  std::vector<Writer> writers_;
};

// Waits for samples on several subscriptions at once (a DDS waitset): the loop of the recorder
// and of the relay, which take from every subscription once any has something.
class WaitSet {
 public:
  static Result<WaitSet> create(const Participant& participant);
  WaitSet() = default;
  WaitSet(WaitSet&& other) noexcept;
  WaitSet& operator=(WaitSet&& other) noexcept;
  ~WaitSet();
  void attach(const Subscription& subscription);
  // Waits up to `timeout_ns` until an attached subscription has samples; returns how many have.
  Result<std::int32_t> wait(std::int64_t timeout_ns);

 private:
  std::int32_t handle_ = 0;
  std::int64_t attached_ = 0;
};

}  // namespace rbsim::node
