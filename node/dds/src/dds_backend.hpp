// The seam's classes on Cyclone DDS (rbsim/middleware_backend.hpp): what create_dds_participant's
// handles hold.
#pragma once

#include <dds/dds.h>
#include <dds/ddsi/ddsi_sertype.h>

#include <memory>
#include <string>
#include <vector>

#include "rbsim/dds.hpp"
#include "rbsim/graph.hpp"
#include "rbsim/middleware_backend.hpp"

namespace rbsim::node {

// A topic by its DDS names; `label` names it in errors.
struct DdsTopic {
  std::string dds_name;  // "rt/rosout", "ros_discovery_info"
  std::string dds_type;  // "rcl_interfaces::msg::dds_::Log_"
  // "rcl_interfaces/msg/Log": the endpoints' USER_DATA carries its REP 2011 type hash
  // (msgs::type_hash) unless EndpointOptions::type_hash says otherwise; empty: no hash.
  std::string ros_type;
  std::string label;
};

// What every DDS endpoint needs of its participant.
struct DdsContext {
  dds_entity_t participant = 0;
  RosDistro distro = RosDistro::Jazzy;
  std::shared_ptr<Graph> graph;  // null while the participant is created (the graph's own writer)
};

class DdsPublisher final : public PublisherImpl {
 public:
  static Result<std::unique_ptr<DdsPublisher>> create(const DdsContext& context, const DdsTopic& topic,
                                                      const QosSpec& qos, const EndpointOptions& options);
  ~DdsPublisher() override;
  Status publish(std::span<const std::byte> cdr, bool (*stop)()) override;
  std::int32_t matched() const override;
  bool wait_for_subscribers(std::int32_t count, bool (*stop)()) const override;
  Status flush(double timeout_s, bool (*stop)()) override;
  dds_entity_t writer() const { return writer_; }

 private:
  DdsPublisher() = default;
  dds_entity_t writer_ = 0, topic_ = 0;
  const ddsi_sertype* sertype_ = nullptr;  // the writer's (raw CDR) type, owned by the topic
  std::string label_;
  std::weak_ptr<Graph> graph_;  // where it is listed (gone with the participant: nothing to unlist)
};

class DdsSubscription final : public SubscriptionImpl {
 public:
  static Result<std::unique_ptr<DdsSubscription>> create(const DdsContext& context, const DdsTopic& topic,
                                                         const msgs::TopicSpec* spec, const QosSpec& qos,
                                                         const EndpointOptions& options);
  ~DdsSubscription() override;
  bool take(Received& out) override;
  std::uint64_t lost() const override;
  std::int32_t matched() const override;
  dds_entity_t reader() const { return reader_; }

 private:
  DdsSubscription() = default;
  dds_entity_t reader_ = 0, topic_ = 0;
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

class DdsWaitSet final : public WaitSetImpl {
 public:
  explicit DdsWaitSet(dds_entity_t handle) : handle_(handle) {}
  ~DdsWaitSet() override;
  void attach(SubscriptionImpl& subscription) override;
  Result<std::int32_t> wait(std::int64_t timeout_ns) override;

 private:
  dds_entity_t handle_ = 0;
  std::int64_t attached_ = 0;
};

class DdsParticipant final : public ParticipantImpl {
 public:
  DdsParticipant(DdsContext context, std::uint32_t domain, std::string description, NodeName node)
      : context_(std::move(context)),
        domain_(domain),
        description_(std::move(description)),
        node_(std::move(node)) {}
  ~DdsParticipant() override;
  DdsParticipant(const DdsParticipant&) = delete;
  DdsParticipant& operator=(const DdsParticipant&) = delete;
  const std::string& description() const override { return description_; }
  const NodeName& node() const override { return node_; }
  Result<std::unique_ptr<PublisherImpl>> create_publisher(const TopicRef& topic, const QosSpec& qos,
                                                          const EndpointOptions& options) override;
  Result<std::unique_ptr<SubscriptionImpl>> create_subscription(const TopicRef& topic, const QosSpec& qos,
                                                                const EndpointOptions& options) override;
  Result<std::unique_ptr<WaitSetImpl>> create_waitset() override;
  Result<std::unique_ptr<ServiceServerImpl>> create_server(std::string_view service,
                                                           std::string_view srv_type,
                                                           const ServiceOptions& options) override;
  Result<std::unique_ptr<ServiceClientImpl>> create_client(std::string_view service,
                                                           std::string_view srv_type,
                                                           const ClientOptions& options) override;

  DdsContext& context() { return context_; }
  const DdsContext& context() const { return context_; }
  std::uint32_t domain() const { return domain_; }

 private:
  DdsContext context_;
  std::uint32_t domain_ = 0;
  std::string description_;
  NodeName node_;
};

// The services (service.cpp).
Result<std::unique_ptr<ServiceServerImpl>> make_dds_server(const DdsContext& context,
                                                           std::string_view service,
                                                           std::string_view srv_type,
                                                           const ServiceOptions& options,
                                                           const DdsServiceUserData& user_data);
Result<std::unique_ptr<ServiceClientImpl>> make_dds_client(const DdsContext& context,
                                                           std::string_view service,
                                                           std::string_view srv_type,
                                                           const ClientOptions& options,
                                                           const DdsServiceUserData& user_data);

// Lists a new endpoint in its participant's graph entry; returns where it is listed.
std::weak_ptr<Graph> list_endpoint(const DdsContext& context, Graph::Kind kind, dds_entity_t entity,
                                   bool in_graph);
// Unlists it (nothing when the graph went first).
void unlist_endpoint(const std::weak_ptr<Graph>& where, dds_entity_t entity);

}  // namespace rbsim::node
