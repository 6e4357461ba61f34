// What the in-memory backend promises beyond what both backends share (rbsim/memory_middleware.hpp):
// the graph it lists, keep-last queues that count what they push out, type and durability
// matching, loans that outlive their subscription, replies to a client that went.
#include <algorithm>

#include "backends.hpp"
#include "rbsim/interfaces.hpp"
#include "rbsim/service.hpp"
#include "rbsim/service_set.hpp"

namespace rbsim::node::test {
namespace {

using Kind = MemoryNetwork::Endpoint::Kind;

struct MemoryBackend : ::testing::Test {
  Participant participant(const std::string& name) {
    Result<Participant> p = create_memory_participant(network, NodeName{"/ns", name});
    EXPECT_TRUE(p.ok());
    return std::move(p.value());
  }
  std::shared_ptr<MemoryNetwork> network = std::make_shared<MemoryNetwork>();
};

const msgs::TopicSpec& clock_spec() {
  return msgs::topic(msgs::TopicId::Clock);
}

// graph(): each participant is a node, with the endpoints listed on the graph, until they go.
TEST_F(MemoryBackend, GraphListsNodesAndTheirEndpoints) {
  Participant a = participant("a");
  {
    Participant b = participant("b");
    auto pub = Publisher::create(a, clock_spec(), "/clock", qos_for(clock_spec()));
    EndpointOptions hidden;
    hidden.in_graph = false;
    auto unlisted = Publisher::create(a, clock_spec(), "/hidden", qos_for(clock_spec()), hidden);
    auto sub = Subscription::create(b, clock_spec(), "/clock", qos_for(clock_spec()));
    ServiceSet services;
    ASSERT_TRUE(services
                    .add(b, "/ns/b", "step", msgs::StepRequest::kService,
                         [](const RequestHeader&, std::span<const std::byte>, Bytes&) { return false; })
                    .ok());
    ClientOptions co;
    co.in_graph = true;
    auto client = ServiceClient::create(a, "/ns/b/step", msgs::StepRequest::kService, co);
    ASSERT_TRUE(pub.ok() && unlisted.ok() && sub.ok() && client.ok());
    const std::vector<MemoryNetwork::Node> graph = network->graph();
    ASSERT_EQ(graph.size(), 2u);
    EXPECT_EQ(graph[0].name.fully_qualified(), "/ns/a");
    EXPECT_EQ(graph[1].name.fully_qualified(), "/ns/b");
    const std::string clock_type(clock_spec().type);
    const std::string step_type(msgs::StepRequest::kService);
    EXPECT_EQ(graph[0].endpoints,
              (std::vector<MemoryNetwork::Endpoint>{{Kind::Publisher, "/clock", clock_type},
                                                    {Kind::ServiceClient, "/ns/b/step", step_type}}));
    EXPECT_EQ(graph[1].endpoints,
              (std::vector<MemoryNetwork::Endpoint>{{Kind::Subscription, "/clock", clock_type},
                                                    {Kind::ServiceServer, "/ns/b/step", step_type}}));
  }
  const std::vector<MemoryNetwork::Node> graph = network->graph();
  ASSERT_EQ(graph.size(), 1u);
  EXPECT_TRUE(graph[0].endpoints.empty());
}

// A keep-last queue keeps the newest `depth` samples and counts those it pushed out as lost.
TEST_F(MemoryBackend, KeepLastQueueDropsTheOldestAndCountsThem) {
  Participant p = participant("p");
  auto pub = Publisher::create(p, clock_spec(), "/clock", QosSpec{false, true, 0});
  auto sub = Subscription::create(p, clock_spec(), "/clock", QosSpec{false, false, 2});
  ASSERT_TRUE(pub.ok() && sub.ok());
  for (std::uint8_t s = 1; s <= 5; ++s) ASSERT_TRUE(pub->publish(clock_cdr(s)).ok());
  EXPECT_EQ(sub->lost(), 3u);
  Received r;
  ASSERT_TRUE(sub->take(r));
  EXPECT_TRUE(std::ranges::equal(r.cdr, clock_cdr(4)));
  ASSERT_TRUE(sub->take(r));
  EXPECT_TRUE(std::ranges::equal(r.cdr, clock_cdr(5)));
  EXPECT_FALSE(sub->take(r));
  EXPECT_FALSE(r.offered.transient_local);
  EXPECT_TRUE(r.offered.keep_all);
}

// A subscription matches a publisher of the same name and type only, and a transient-local one no
// volatile publisher; matched() follows endpoints as they come and go.
TEST_F(MemoryBackend, MatchesByNameTypeAndDurability) {
  Participant p = participant("p");
  auto pub = Publisher::create(p, clock_spec(), "/t", QosSpec{false, false, 10});
  auto other_type = Subscription::create(p, RawTopic{"/t", std::string(msgs::ParameterEvent::kType)},
                                         QosSpec{false, false, 10});
  auto wants_durability = Subscription::create(p, clock_spec(), "/t", QosSpec{true, false, 10});
  ASSERT_TRUE(pub.ok() && other_type.ok() && wants_durability.ok());
  EXPECT_EQ(pub->matched(), 0);
  EXPECT_EQ(other_type->matched(), 0);
  EXPECT_EQ(wants_durability->matched(), 0);
  ASSERT_TRUE(pub->publish(clock_cdr(1)).ok());
  Received r;
  EXPECT_FALSE(other_type->take(r));
  EXPECT_FALSE(wants_durability->take(r));
  {
    auto sub = Subscription::create(p, clock_spec(), "/t", QosSpec{false, false, 10});
    ASSERT_TRUE(sub.ok());
    EXPECT_EQ(pub->matched(), 1);
    EXPECT_EQ(sub->matched(), 1);
  }
  EXPECT_EQ(pub->matched(), 0);
}

// A taken sample stays valid after its subscription and publisher are gone; a move keeps it.
TEST_F(MemoryBackend, LoanOutlivesItsSubscription) {
  Participant p = participant("p");
  Received kept;
  {
    auto pub = Publisher::create(p, clock_spec(), "/t", QosSpec{false, false, 10});
    auto sub = Subscription::create(p, clock_spec(), "/t", QosSpec{false, false, 10});
    ASSERT_TRUE(pub.ok() && sub.ok());
    ASSERT_TRUE(pub->publish(clock_cdr(9)).ok());
    Received r;
    ASSERT_TRUE(sub->take(r));
    kept = std::move(r);
  }
  ASSERT_TRUE(kept.held);
  EXPECT_TRUE(std::ranges::equal(kept.cdr, clock_cdr(9)));
}

// A client that goes before its reply gets none: the server counts it and moves on.
TEST_F(MemoryBackend, ReplyToAClientThatWentIsCountedGone) {
  Participant p = participant("p");
  auto server = ServiceServer::create(p, "/s", msgs::StepRequest::kService);
  ASSERT_TRUE(server.ok());
  {
    auto client = ServiceClient::create(p, "/s", msgs::StepRequest::kService);
    ASSERT_TRUE(client.ok());
    Bytes req;
    msgs::encode(msgs::StepRequest{1}, req);
    ASSERT_TRUE(client->send(req).ok());
  }
  EXPECT_EQ(server->serve([](const RequestHeader&, std::span<const std::byte>, Bytes& reply) {
    msgs::encode(msgs::StepResponse{}, reply);
    return true;
  }),
            1u);
  const ServiceStats s = server->stats();
  EXPECT_EQ(s.client_gone, 1u);
  EXPECT_EQ(s.answered, 0u);
  EXPECT_EQ(s.pending, 0u);
}

// Participants of different networks do not see each other.
TEST_F(MemoryBackend, NetworksAreSeparate) {
  auto other = std::make_shared<MemoryNetwork>();
  Participant here = participant("here");
  Result<Participant> there = create_memory_participant(other, NodeName{"/", "there"});
  ASSERT_TRUE(there.ok());
  auto pub = Publisher::create(here, clock_spec(), "/t", QosSpec{false, false, 10});
  auto sub = Subscription::create(there.value(), clock_spec(), "/t", QosSpec{false, false, 10});
  ASSERT_TRUE(pub.ok() && sub.ok());
  EXPECT_EQ(pub->matched(), 0);
  EXPECT_EQ(network->graph().size(), 1u);
  EXPECT_EQ(other->graph().size(), 1u);
  EXPECT_FALSE(create_memory_participant(nullptr, NodeName{}).ok());
}

}  // namespace
}  // namespace rbsim::node::test
