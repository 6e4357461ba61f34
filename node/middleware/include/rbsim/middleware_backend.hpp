// What a middleware implements under the seam (rbsim/middleware.hpp, rbsim/service.hpp): one class
// per handle, virtual here and nowhere else in the node's modules. A backend's participant
// creates the others; the handles forward to them and add nothing but their names.
//
// A backend lists a node's endpoints on its graph itself (EndpointOptions::in_graph,
// ServiceOptions::in_graph) and works out what it announces of their types (REP 2011 hashes).
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>

#include "rbsim/middleware.hpp"
#include "rbsim/service.hpp"

namespace rbsim::node {

// A topic as the seam names it: its ROS name and type and, for one of msgs::topics(), its spec.
struct TopicRef {
  std::string ros_name;  // "/rbsim/body_states", "/rosout"
  std::string ros_type;  // "rbsim_msgs/msg/BodyStates"
  const msgs::TopicSpec* spec = nullptr;
};

class PublisherImpl {
 public:
  virtual ~PublisherImpl() = default;
  virtual Status publish(std::span<const std::byte> cdr, bool (*stop)()) = 0;
  virtual std::int32_t matched() const = 0;
  virtual bool wait_for_subscribers(std::int32_t count, bool (*stop)()) const = 0;
  virtual Status flush(double timeout_s, bool (*stop)()) = 0;
};

class SubscriptionImpl {
 public:
  virtual ~SubscriptionImpl() = default;
  virtual bool take(Received& out) = 0;
  virtual std::uint64_t lost() const = 0;
  virtual std::int32_t matched() const = 0;
};

class WaitSetImpl {
 public:
  virtual ~WaitSetImpl() = default;
  virtual void attach(SubscriptionImpl& subscription) = 0;
  virtual Result<std::int32_t> wait(std::int64_t timeout_ns) = 0;
};

class ServiceServerImpl {
 public:
  virtual ~ServiceServerImpl() = default;
  virtual std::size_t serve(const ServiceHandler& handler, std::size_t budget) = 0;
  virtual void reply(const RequestHeader& header, std::span<const std::byte> body) = 0;
  virtual bool wait(double timeout_s) = 0;
  virtual ServiceStats stats() const = 0;
};

class ServiceClientImpl {
 public:
  virtual ~ServiceClientImpl() = default;
  virtual bool server_ready() const = 0;
  virtual Status wait_for_server(double timeout_s) = 0;
  virtual Result<std::int64_t> send(std::span<const std::byte> request) = 0;
  virtual bool take_reply(RequestHeader& header, Bytes& reply) = 0;
  virtual bool wait_reply(double timeout_s) = 0;
  virtual std::uint64_t id() const = 0;
};

class ParticipantImpl {
 public:
  virtual ~ParticipantImpl() = default;
  virtual const std::string& description() const = 0;
  virtual const NodeName& node() const = 0;
  virtual Result<std::unique_ptr<PublisherImpl>> create_publisher(const TopicRef& topic, const QosSpec& qos,
                                                                  const EndpointOptions& options) = 0;
  virtual Result<std::unique_ptr<SubscriptionImpl>> create_subscription(const TopicRef& topic,
                                                                        const QosSpec& qos,
                                                                        const EndpointOptions& options) = 0;
  virtual Result<std::unique_ptr<WaitSetImpl>> create_waitset() = 0;
  virtual Result<std::unique_ptr<ServiceServerImpl>> create_server(std::string_view service,
                                                                   std::string_view srv_type,
                                                                   const ServiceOptions& options) = 0;
  virtual Result<std::unique_ptr<ServiceClientImpl>> create_client(std::string_view service,
                                                                   std::string_view srv_type,
                                                                   const ClientOptions& options) = 0;
};

}  // namespace rbsim::node
